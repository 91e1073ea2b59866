//! Robots beyond the generator's limits are refused with a message that names the limit and
//! how to raise it.

use std::path::PathBuf;

fn urdf(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/robots")
        .join(format!("{robot}.urdf"))
}

#[test]
fn robots_beyond_the_joint_limit_are_refused_with_the_way_to_raise_it() {
    let err = eomgen::Builder::new(urdf("panda"))
        .max_dof(8)
        .generate()
        .unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(
            err,
            eomgen::Error::Limit {
                value: 9,
                limit: 8,
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.contains("panda.urdf") && msg.contains("Builder::max_dof"),
        "{msg}"
    );
    assert!(eomgen::Builder::new(urdf("panda"))
        .max_dof(9)
        .generate()
        .is_ok());
}

#[test]
fn derivations_beyond_the_graph_limit_are_refused_with_the_way_to_raise_it() {
    for robot in ["ur5", "panda"] {
        let err = eomgen::Builder::new(urdf(robot))
            .max_graph_nodes(5_000)
            .generate()
            .unwrap_err();
        let msg = err.to_string();
        match err {
            eomgen::Error::Limit {
                value,
                limit: 5_000,
                raise: "Builder::max_graph_nodes",
                ..
            } => assert!(value > 5_000, "{msg}"),
            _ => panic!("{robot}: not the graph limit: {msg}"),
        }
        assert!(
            msg.contains(&format!("{robot}.urdf")) && msg.contains("expression graph nodes"),
            "{msg}"
        );
    }
    // The same robot passes with room to spare, and its output does not depend on the limit.
    let roomy = eomgen::Builder::new(urdf("ur5"))
        .max_graph_nodes(2_000_000)
        .generate()
        .unwrap();
    // (Only the banner's Regenerate line, which records the option, differs.)
    let code = |s: &str| {
        s.lines()
            .filter(|l| !l.starts_with("// Regenerate: "))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let default = eomgen::Builder::new(urdf("ur5")).generate().unwrap();
    assert!(roomy.contains("--max-graph-nodes 2000000"));
    assert_eq!(code(&roomy), code(&default));
}

#[test]
fn a_full_graph_stops_growing_and_reports_instead_of_panicking() {
    use eomgen::cas::{Graph, Limits};
    for max_nodes in [0, 1, 2, 3, 50] {
        let mut g = Graph::with_limits(Limits {
            max_nodes,
            ..Limits::default()
        });
        let x = g.q(0);
        let mut e = x;
        for k in 0..200 {
            let s = g.sin(e);
            let c = g.constant(k as f64 + 0.5);
            e = g.add(s, c);
        }
        // 0 and 1 always exist; nothing beyond the limit was stored.
        assert!(g.len() <= max_nodes.max(2), "{max_nodes}: {}", g.len());
        let full = g.check().unwrap_err();
        assert_eq!(full.max_nodes, max_nodes);
        assert!(full.nodes > max_nodes, "{full:?}");
    }
    let mut g = Graph::new();
    let x = g.q(0);
    g.sin(x);
    assert!(g.check().is_ok());
}
