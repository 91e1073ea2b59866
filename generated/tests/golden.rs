//! Regenerates every checked-in file in memory and fails on any byte of difference, like
//! prost-build's bootstrap test. `EOMGEN_BLESS=1` rewrites the files instead.

use std::path::PathBuf;

use eomgen_generated::ROBOTS;

const REFRESH: &str = "EOMGEN_BLESS=1 cargo test -p eomgen-generated --test golden";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The first differing lines, with a little context.
fn diff(old: &str, new: &str) -> String {
    let (a, b): (Vec<&str>, Vec<&str>) = (old.lines().collect(), new.lines().collect());
    let first = a.iter().zip(&b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
    let mut out = format!("first difference at line {} ({} lines checked in, {} generated)\n", first + 1, a.len(), b.len());
    for k in first.saturating_sub(2)..(first + 5) {
        if let Some(x) = a.get(k) {
            out.push_str(&format!("- {x}\n"));
        }
        if let Some(y) = b.get(k) {
            out.push_str(&format!("+ {y}\n"));
        }
    }
    out
}

#[test]
fn checked_in_code_is_what_eomgen_generates() {
    let bless = std::env::var_os("EOMGEN_BLESS").is_some();
    let mut stale = Vec::new();
    for (module, ty, urdf) in ROBOTS {
        let generated = eomgen::Builder::new(root().join("robots").join(urdf))
            .type_name(ty)
            .module_name(module)
            .regenerate_hint(REFRESH)
            .generate()
            .unwrap_or_else(|e| panic!("{urdf}: {e}"));
        let path = root().join("src").join(format!("{module}.rs"));
        let current = std::fs::read_to_string(&path).unwrap_or_default();
        if current != generated {
            if bless {
                eomgen::write_if_changed(&path, generated.as_bytes()).unwrap();
            } else {
                stale.push(format!("{}:\n{}", path.display(), diff(&current, &generated)));
            }
        }
    }
    assert!(stale.is_empty(), "generated code is stale; refresh with `{REFRESH}`\n\n{}", stale.join("\n"));
}
