//! Every single-quantity selection (`Builder::quantities([name])`, `generate --only name`)
//! compiles, on robots large enough that forward dynamics, `M^-1`, the derivatives of forward
//! dynamics and Craig's matrices are composed at run time from other generated functions: a
//! 28-joint serial chain with a fixed base and a 20-joint one on a floating base with two contact
//! points, both with the derivatives. A selection must bring what it calls, and what that calls.
//!
//! The 37 modules are written into one throwaway crate under Cargo's test scratch directory
//! (`target/tmp/selections_compile`) and checked there with `cargo check --offline`, warnings
//! denied (name resolution and types without code generation: enough to catch a call to a
//! function that was not generated, or an item nothing uses). They are 27 MB of source: from a
//! fresh target directory the test takes 110 s of CPU (the nested build of the runtime, the
//! check, the generation), a fifth of all of `cargo test --workspace`. So it is ignored there
//! and CI runs it by name (`.ci/run`):
//!
//! ```sh
//! cargo test -p eomgen --test selections_compile -- --ignored
//! ```

#[path = "support/chain.rs"]
mod chain;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use eomgen::dynamics::{catalogue, Derivation, Evaluation};
use eomgen::emit::{self, EmitOptions};

const TYPE_NAME: &str = "Chain";

/// A robot whose every single-quantity selection is generated.
struct Robot {
    /// The module-name prefix in the checked crate.
    prefix: &'static str,
    builder: eomgen::Builder,
    file: String,
}

fn robots() -> Vec<Robot> {
    let chain = |n: usize| {
        let file = format!("chain{n}.urdf");
        let b = eomgen::Builder::from_urdf_str(&chain::serial_chain_urdf(n), &file)
            .type_name(TYPE_NAME)
            .derivatives()
            // M^-1 and the forward-dynamics derivatives composed at run time: since M^-1 is
            // formed as X D^-1 X^T, a 24-joint chain's is short enough to be straight-line.
            .derivatives_flat_max_ops(0);
        (b, file)
    };
    let (fixed, fixed_file) = chain(28);
    let (floating, floating_file) = chain(20);
    vec![
        Robot {
            prefix: "fixed",
            builder: fixed,
            file: fixed_file,
        },
        Robot {
            prefix: "floating",
            // Contact forward dynamics solved at run time, as its `_active` variant is: the
            // straight-line route is every other quantity's kind of code.
            builder: floating
                .floating_base()
                .contact_points(&["link20", "link10"])
                .contact_forward_dynamics_flat_max_ops(0),
            file: floating_file,
        },
    ]
}

/// The robot's full derivation, checked to take the run-time routes this test is about.
fn derive(robot: &Robot) -> (eomgen::model::Model, Derivation) {
    let model = robot.builder.model().unwrap();
    let d = robot.builder.derive(&model).unwrap();
    let eval = |name: &str| &d.quantity(name).unwrap().eval;
    assert!(
        matches!(
            eval("forward_dynamics"),
            Evaluation::ForwardDynamicsSolve { .. }
        ),
        "{}: forward dynamics is unrolled; take a longer chain",
        robot.file
    );
    assert!(
        matches!(eval("mass_matrix_inverse"), Evaluation::MassMatrixInverse),
        "{}: M^-1 is straight-line despite derivatives_flat_max_ops(0)",
        robot.file
    );
    assert!(
        matches!(
            eval("forward_dynamics_derivatives"),
            Evaluation::ForwardDynamicsDerivatives { .. }
        ),
        "{}: the forward-dynamics derivatives are straight-line despite derivatives_flat_max_ops(0)",
        robot.file
    );
    if model.is_floating() {
        assert!(matches!(
            eval("contact_forward_dynamics"),
            Evaluation::ContactForwardDynamics { .. }
        ));
    } else {
        assert!(matches!(eval("centrifugal"), Evaluation::CraigColumns(_)));
    }
    (model, d)
}

/// Writes `path` unless it already holds `text` (so that an unchanged crate is not re-checked).
fn write(path: &Path, text: &str) {
    if std::fs::read_to_string(path).ok().as_deref() != Some(text) {
        std::fs::write(path, text).unwrap();
    }
}

/// Generates one module per robot and quantity into `src/`, returning the crate root's text.
fn generate_modules(src: &Path) -> String {
    let mut lib = String::from(
        "//! Every single-quantity selection of the test robots, one module each.\n\
         #![no_std]\n#![deny(warnings)]\n",
    );
    for robot in robots() {
        let (model, mut d) = derive(&robot);
        let all = std::mem::take(&mut d.quantities);
        let opts = EmitOptions {
            type_name: TYPE_NAME.into(),
            source_name: robot.file.clone(),
            regenerate: "selections_compile".into(),
            max_function_ops: eomgen::DEFAULT_MAX_FUNCTION_OPS,
            max_derivative_function_ops: eomgen::DEFAULT_MAX_DERIVATIVE_FUNCTION_OPS,
        };
        let names = catalogue::names(&all);
        for (k, name) in names.iter().enumerate() {
            // What `Builder::quantities([name])` does after deriving, without deriving again.
            d.quantities = catalogue::select(all.clone(), &[name.to_string()]).unwrap();
            let source = emit::rust_module(&model, &d, &opts).unwrap().source;
            if k == 0 {
                // The shortcut is the builder's route: same source as through the builder.
                let through_builder = robot
                    .builder
                    .clone()
                    .regenerate_hint("selections_compile")
                    .quantities([*name])
                    .generate()
                    .unwrap();
                assert_eq!(source, through_builder, "{} {name}", robot.file);
            }
            let module = format!("{}_{name}", robot.prefix);
            write(&src.join(format!("{module}.rs")), &source);
            let _ = writeln!(lib, "pub mod {module} {{ include!(\"{module}.rs\"); }}");
        }
    }
    lib
}

#[test]
#[ignore = "110 s of CPU from cold: CI runs it, `cargo test -p eomgen --test selections_compile -- --ignored`"]
fn every_single_quantity_selection_compiles() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("selections_compile");
    let src = dir.join("src");
    std::fs::create_dir_all(&src).unwrap();

    let runtime: PathBuf = manifest.join("../runtime").canonicalize().unwrap();
    // An empty `[workspace]`: the crate lies inside this workspace's target directory but is
    // not one of its members.
    let cargo_toml = format!(
        "[package]\nname = \"selections\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\neomgen-runtime = {{ path = '{}' }}\n\n[workspace]\n",
        runtime.display()
    );
    write(&dir.join("Cargo.toml"), &cargo_toml);
    // The workspace's lock file: the runtime's dependencies at the versions already downloaded,
    // so that `--offline` resolves.
    let lock = std::fs::read_to_string(manifest.join("../Cargo.lock")).unwrap();
    write(&dir.join("Cargo.lock"), &lock);
    let lib = generate_modules(&src);
    write(&src.join("lib.rs"), &lib);

    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args(["check", "--offline", "--quiet", "--message-format", "short"])
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        // Its own target directory: the outer build's may be locked by the cargo running us.
        .arg("--target-dir")
        .arg(dir.join("target"))
        // Checked once per change of the generator: incremental caches would cost more than
        // they save (and 40 MB).
        .env("CARGO_INCREMENTAL", "0")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let first: Vec<&str> = stderr.lines().take(40).collect();
    assert!(
        out.status.success(),
        "a single-quantity selection does not compile ({}):\n{}",
        dir.display(),
        first.join("\n")
    );
}
