//! The command line names its own flags for the generator's limits.

mod support;

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
