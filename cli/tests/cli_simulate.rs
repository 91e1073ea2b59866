//! `eomgen simulate`: CSV layout, energy conservation without a controller, the closed-loop
//! error of computed torque against its analytical decay, and input errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::scratch;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace holds cli/")
        .to_path_buf()
}

/// Runs the binary from the workspace root.
fn eomgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eomgen"))
        .args(args)
        .current_dir(workspace())
        .output()
        .expect("the binary runs")
}

#[track_caller]
fn ok(args: &[&str]) -> String {
    let out = eomgen(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8")
}

fn rows(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect()
}

#[test]
fn passive_double_pendulum_csv_and_energy() {
    let csv = ok(&[
        "simulate",
        "tests/robots/double_pendulum.urdf",
        "--duration",
        "0.5",
        "--dt",
        "1e-3",
        "--q0",
        "1.8,1.2",
        "--qd0",
        "1,2",
    ]);
    let header = csv.lines().next().unwrap();
    assert_eq!(
        header,
        "t,q_joint1,q_joint2,qd_joint1,qd_joint2,tau_joint1,tau_joint2"
    );
    let r = rows(&csv);
    assert_eq!(r.len(), 501, "initial state and one row per step");
    assert_eq!(r[0], vec![0.0, 1.8, 1.2, 1.0, 2.0, 0.0, 0.0]);
    assert!((r[500][0] - 0.5).abs() < 1e-12);
    // The summary reports the energy change; RK4 at 1 ms keeps it tiny.
    let (_guard, dir) = scratch("sim");
    let file = dir.join("dp.csv");
    let summary = ok(&[
        "simulate",
        "tests/robots/double_pendulum.urdf",
        "--duration",
        "0.5",
        "--q0",
        "1.8,1.2",
        "--qd0",
        "1,2",
        "--csv",
        file.to_str().unwrap(),
    ]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), csv);
    let change: f64 = summary
        .split("(change ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .expect("energy change in the summary")
        .parse()
        .unwrap();
    assert!(change.abs() < 1e-7, "{summary}");
}

/// Every CSV field is the shortest text that reads back to its number, in exponent form when
/// that is shorter: a pendulum starting from rest at its bottom moves by nanometres, printed
/// as `-1.7656506192700173e-9`, not `-0.0000000017656506192700173`.
#[test]
fn csv_numbers_are_shortest_round_trip() {
    let csv = ok(&[
        "simulate",
        "tests/robots/double_pendulum.urdf",
        "--duration",
        "0.01",
        "--dt",
        "1e-3",
    ]);
    let fields: Vec<&str> = csv.lines().skip(1).flat_map(|l| l.split(',')).collect();
    assert_eq!(fields.len(), 11 * 7);
    for field in &fields {
        let x: f64 = field.parse().expect("a number");
        let (positional, exponent) = (format!("{x}"), format!("{x:e}"));
        let shortest = if exponent.len() < positional.len() {
            exponent
        } else {
            positional
        };
        assert_eq!(*field, shortest, "not the shortest form");
    }
    assert!(
        fields.iter().any(|f| f.contains("e-9")),
        "tiny positions in exponent form: {csv}"
    );
}

#[test]
fn computed_torque_error_decays_as_critically_damped() {
    // From rest 0.2 rad off the target: e(t) = e0 (1 + w t) exp(-w t) in every joint.
    let csv = ok(&[
        "simulate",
        "tests/robots/ur5.urdf",
        "--duration",
        "0.6",
        "--q0",
        "0.1,-1.2,1.4,-1,-1.5,0.3",
        "--target",
        "0.3,-1,1.2,-0.8,-1.3,0.5",
        "--controller",
        "computed-torque",
        "--omega",
        "10",
    ]);
    let target = [0.3, -1.0, 1.2, -0.8, -1.3, 0.5];
    for r in rows(&csv).iter().step_by(100) {
        let t = r[0];
        let want = 0.2 * (1.0 + 10.0 * t) * (-10.0 * t).exp();
        for i in 0..6 {
            let e = (target[i] - r[1 + i]).abs();
            assert!((e - want).abs() < 1e-9, "t = {t}, joint {i}: {e} vs {want}");
        }
    }
}

#[test]
fn gravity_compensation_holds_still_and_bad_input_fails() {
    let csv = ok(&[
        "simulate",
        "tests/robots/ur5.urdf",
        "--duration",
        "0.2",
        "--q0",
        "0.1,-1.2,1.4,-1,-1.5,0.3",
        "--controller",
        "gravity-comp",
    ]);
    let last = rows(&csv).pop().unwrap();
    for (i, q) in [0.1, -1.2, 1.4, -1.0, -1.5, 0.3].iter().enumerate() {
        assert!((last[1 + i] - q).abs() < 1e-12);
    }
    let out = eomgen(&["simulate", "tests/robots/ur5.urdf", "--q0", "1,2"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("eomgen: error: --q0 has 2 value(s)"),
        "{err}"
    );
    let out = eomgen(&["simulate", "tests/robots/ur5.urdf", "--dt", "0"]);
    assert_eq!(out.status.code(), Some(1));
}

/// `--friction` applies the URDF's `<dynamics damping friction>`: the double pendulum's
/// energy then drops, and computed torque on the allegro hand (damping and Coulomb friction on
/// every joint) compensates it exactly, so the error still decays as `(1 + w t) exp(-w t)`.
#[test]
fn friction_dissipates_and_computed_torque_compensates_it() {
    let change = |extra: &[&str]| -> f64 {
        let (_guard, dir) = scratch("fric");
        let file = dir.join("dp.csv");
        let mut args = vec![
            "simulate",
            "tests/robots/double_pendulum.urdf",
            "--duration",
            "0.5",
            "--q0",
            "1.8,1.2",
            "--qd0",
            "1,2",
            "--csv",
            file.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let summary = ok(&args);
        summary
            .split("(change ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .unwrap()
            .parse()
            .unwrap()
    };
    let (free, damped) = (change(&[]), change(&["--friction"]));
    assert!(free.abs() < 1e-7 && damped < -1e-3, "{free} {damped}");

    let q0 = "0.1,0.2,0.3,0.2,1.0,0.3,0.2,0.1,0.0,0.3,0.2,0.1,0.0,0.3,0.2,0.1";
    let target: Vec<f64> = q0
        .split(',')
        .map(|x| x.parse::<f64>().unwrap() + 0.1)
        .collect();
    let target_arg = target
        .iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",");
    let csv = ok(&[
        "simulate",
        "tests/robots/allegro_right_hand.urdf",
        "--duration",
        "0.3",
        "--q0",
        q0,
        "--target",
        &target_arg,
        "--controller",
        "computed-torque",
        "--omega",
        "10",
        "--friction",
    ]);
    for r in rows(&csv).iter().step_by(100) {
        let want = 0.1 * (1.0 + 10.0 * r[0]) * (-10.0 * r[0]).exp();
        for i in 0..16 {
            let e = (target[i] - r[1 + i]).abs();
            assert!(
                (e - want).abs() < 1e-8,
                "t = {}, joint {i}: {e} vs {want}",
                r[0]
            );
        }
    }
}

/// The energy change printed by the summary (`change X J`).
fn energy_change(summary: &str) -> f64 {
    let line = summary
        .lines()
        .find(|l| l.starts_with("energy:"))
        .expect("energy line");
    let change = line.split("change ").nth(1).expect("change");
    change.trim_end_matches(" J)").parse().expect("number")
}

/// `--integrator`: the symplectic methods agree with RK4 on a short run and keep the energy of
/// the undamped double pendulum (the runtime's test measures the long runs).
#[test]
fn integrators() {
    let (_guard, dir) = scratch("integrators");
    let out = dir.join("integrators.csv");
    let mut finals = Vec::new();
    for (integrator, name, tolerance) in [
        ("rk4", "RK4", 1e-7),
        ("symplectic-euler", "symplectic Euler", 1e-3),
        ("implicit-midpoint", "implicit midpoint", 1e-6),
        ("yoshida4", "Yoshida 4", 1e-8),
    ] {
        let summary = ok(&[
            "simulate",
            "tests/robots/double_pendulum.urdf",
            "--q0",
            "3.4416,-0.3",
            "--dt",
            "3e-3",
            "--duration",
            "3",
            "--integrator",
            integrator,
            "--csv",
            out.to_str().unwrap(),
        ]);
        assert!(
            summary.contains(&format!("1000 {name} steps of 0.003 s")),
            "{summary}"
        );
        let change = energy_change(&summary);
        assert!(
            change.abs() < tolerance,
            "{integrator}: energy change {change}"
        );
        let csv = std::fs::read_to_string(&out).unwrap();
        finals.push(rows(&csv).last().unwrap()[1..3].to_vec());
    }
    // Second and fourth order methods end where RK4 does, to their accuracy.
    for (k, tol) in [(2, 1e-2), (3, 1e-4)] {
        for j in 0..2 {
            assert!((finals[k][j] - finals[0][j]).abs() < tol, "{finals:?}");
        }
    }
}

/// `--controller pfl` on the acrobot with its elbow passive (`--passive elbow`): no effort on
/// the elbow, the shoulder at its target; with `--swing` the energy grows.
#[test]
fn acrobot_collocated_pfl() {
    let csv = ok(&[
        "simulate",
        "tests/fixtures/acrobot.urdf",
        "--passive",
        "elbow",
        "--controller",
        "pfl",
        "--omega",
        "4",
        "--target",
        "0.8,0",
        "--duration",
        "3",
    ]);
    let r = rows(&csv);
    // t, q_shoulder, q_elbow, qd_shoulder, qd_elbow, tau_shoulder, tau_elbow
    assert!(r.iter().all(|row| row[6] == 0.0));
    let last = r.last().unwrap();
    let want = 0.8 - 0.8 * (1.0 + 4.0 * 3.0) * (-12.0f64).exp();
    assert!((last[1] - want).abs() < 1e-6, "{last:?}");
    let (_guard, dir) = scratch("pfl");
    let out = dir.join("pfl.csv");
    let summary = ok(&[
        "simulate",
        "tests/fixtures/acrobot.urdf",
        "--passive",
        "elbow",
        "--controller",
        "pfl",
        "--omega",
        "6",
        "--swing",
        "-1",
        "--q0",
        "0,0.1",
        "--duration",
        "10",
        "--csv",
        out.to_str().unwrap(),
    ]);
    assert!(energy_change(&summary) > 10.0, "{summary}");

    let err = eomgen(&[
        "simulate",
        "tests/fixtures/acrobot.urdf",
        "--controller",
        "pfl",
    ]);
    assert!(!err.status.success());
    assert!(String::from_utf8_lossy(&err.stderr).contains(
        "tests/fixtures/acrobot.urdf: --controller pfl needs exactly one passive joint (--passive JOINT), not 0"
    ));
    let err = eomgen(&[
        "simulate",
        "tests/fixtures/acrobot.urdf",
        "--passive",
        "wrist",
    ]);
    assert!(String::from_utf8_lossy(&err.stderr)
        .contains("tests/fixtures/acrobot.urdf: passive joints: joint `wrist` does not exist"));
}
