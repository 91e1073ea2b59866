//! Regenerates every checked-in file in memory and fails on any byte of difference, like
//! prost-build's bootstrap test. `EOMGEN_BLESS=1` rewrites the files instead.

use std::path::PathBuf;

use eomgen_generated::{FLOATING_ROBOTS, ROBOTS};

const REFRESH: &str = "EOMGEN_BLESS=1 cargo test -p eomgen-generated --test golden";

/// The reference robots' URDFs: the workspace's `tests/robots/`, beside Pinocchio's values.
fn robots() -> PathBuf {
    root().join("../tests/robots")
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The first differing lines, with a little context.
fn diff(old: &str, new: &str) -> String {
    let (a, b): (Vec<&str>, Vec<&str>) = (old.lines().collect(), new.lines().collect());
    let first = a
        .iter()
        .zip(&b)
        .position(|(x, y)| x != y)
        .unwrap_or(a.len().min(b.len()));
    let mut out = format!(
        "first difference at line {} ({} lines checked in, {} generated)\n",
        first + 1,
        a.len(),
        b.len()
    );
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
    let fixed = ROBOTS.iter().map(|r| (r, false));
    let floating = FLOATING_ROBOTS.iter().map(|r| (r, true));
    for ((module, ty, urdf), floats) in fixed.chain(floating) {
        let builder = eomgen::Builder::new(robots().join(urdf));
        let builder = if floats {
            builder.floating_base()
        } else {
            builder
        };
        let generated = builder
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
                stale.push(format!(
                    "{}:\n{}",
                    path.display(),
                    diff(&current, &generated)
                ));
            }
        }
    }
    assert!(
        stale.is_empty(),
        "generated code is stale; refresh with `{REFRESH}`\n\n{}",
        stale.join("\n")
    );
}

/// The readable equations in `equations/` (M, B, C and G): expanded formulas for the double
/// pendulum (text and Markdown), shared temporaries then entries for the larger robots. Each
/// file is what the `eomgen show` command in its first line prints.
#[test]
fn checked_in_equations_are_what_eomgen_prints() {
    use eomgen::report::{render, Form, Format, ShowOptions};
    let bless = std::env::var_os("EOMGEN_BLESS").is_some();
    let mut stale = Vec::new();
    for (module, _, urdf) in ROBOTS {
        let model = eomgen::urdf::load_file(robots().join(urdf), &Default::default())
            .unwrap_or_else(|e| panic!("{urdf}: {e}"));
        let derivation = eomgen::dynamics::Derivation::new(&model);
        let (form, flag, formats) = if module == "double_pendulum" {
            (Form::Expanded, "", &[Format::Text, Format::Markdown][..])
        } else {
            (Form::Program, " --form program", &[Format::Text][..])
        };
        for &format in formats {
            let opts = ShowOptions {
                terms: ["M", "B", "C", "G"].map(String::from).to_vec(),
                format,
                form,
                source: Some(urdf.to_string()),
                ..Default::default()
            };
            let text = render(&model, &derivation, &opts).unwrap_or_else(|e| panic!("{urdf}: {e}"));
            let (ext, format_flag) = match format {
                Format::Markdown => ("md", " --format markdown"),
                _ => ("txt", ""),
            };
            let banner = format!(
                "Printed by `eomgen show tests/robots/{urdf} --term M,B,C,G{flag}{format_flag}`. Do not \
                 edit: refresh with `{REFRESH}`."
            );
            let generated = match format {
                Format::Markdown => format!("<!-- {banner} -->\n\n{text}"),
                _ => format!("{banner}\n\n{text}"),
            };
            let path = root().join("equations").join(format!("{module}.{ext}"));
            let current = std::fs::read_to_string(&path).unwrap_or_default();
            if current != generated {
                if bless {
                    std::fs::create_dir_all(root().join("equations")).unwrap();
                    eomgen::write_if_changed(&path, generated.as_bytes()).unwrap();
                } else {
                    stale.push(format!(
                        "{}:\n{}",
                        path.display(),
                        diff(&current, &generated)
                    ));
                }
            }
        }
    }
    assert!(
        stale.is_empty(),
        "equations are stale; refresh with `{REFRESH}`\n\n{}",
        stale.join("\n")
    );
}
