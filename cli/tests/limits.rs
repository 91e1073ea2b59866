//! The command line names its own flags for the generator's limits.

use crate::support;

use support::{eomgen, one_line_error, robot};

#[test]
fn show_names_the_graph_limit_when_expansion_fills_the_graph() {
    // Just enough nodes for the derivation, not for the expansion.
    let builder = eomgen::Builder::new(robot("double_pendulum"));
    let derived = builder.derive(&builder.model().unwrap()).unwrap();
    let limit = (derived.graph.len() + 2).to_string();
    let urdf = robot("double_pendulum");
    let urdf = urdf.to_str().unwrap();
    let stderr = one_line_error(&eomgen(&["show", urdf, "--max-graph-nodes", &limit]));
    assert!(
        stderr.contains("double_pendulum.urdf")
            && stderr.contains(&format!("limit of {limit} nodes"))
            && stderr.contains("while expanding the equations")
            && stderr.contains("--max-graph-nodes"),
        "{stderr}"
    );
    // In program form nothing is expanded: the same limit suffices.
    let out = eomgen(&[
        "show",
        urdf,
        "--max-graph-nodes",
        &limit,
        "--form",
        "program",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_joint_limit_names_the_flag() {
    let urdf = robot("panda");
    let stderr = one_line_error(&eomgen(&[
        "generate",
        urdf.to_str().unwrap(),
        "--max-dof",
        "8",
    ]));
    assert!(
        stderr.contains("panda.urdf") && stderr.contains("raise it with --max-dof"),
        "{stderr}"
    );
}

/// The README states the limits the code has, in its table of limits and in the builder
/// section.
#[test]
fn the_readme_states_the_limits_of_the_code() {
    let readme = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"),
    )
    .expect("README.md");
    let max = eomgen::DEFAULT_MAX_DOF;
    let nodes = eomgen::DEFAULT_MAX_GRAPH_NODES / 1_000_000;
    for line in [
        format!("| degrees of freedom | {max} | `Builder::max_dof`, `--max-dof` |"),
        format!("| expression graph nodes of the derivation | {nodes} million "),
        format!(
            "| XML element nesting | {} levels | fixed (`eomgen::urdf::MAX_DEPTH`) |",
            eomgen::urdf::MAX_DEPTH
        ),
        format!(
            "| magnitude of a number that enters the equations | {:e} | fixed",
            eomgen::model::MAX_MAGNITUDE
        ),
        format!("than {max} joints are refused"),
    ] {
        assert!(readme.contains(&line), "the README lacks `{line}`");
    }
}
