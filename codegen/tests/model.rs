//! The URDF → model stage: reference robots against Pinocchio, a handmade robot against hand
//! computations, one test per kind of bad input, and no-panic proptests (the model alone, and
//! through to generated code).

use std::collections::HashSet;
use std::path::PathBuf;

use eomgen::model::{
    JointKind, Limits, Mimic, Model, ModelError, ModelOptions, ModelWarning, SymbolicParams,
    Transform,
};
use eomgen::urdf::{load_file, load_str};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;

const ROBOTS: [&str; 5] = [
    "allegro_right_hand",
    "double_pendulum",
    "kinova",
    "panda",
    "ur5",
];

fn robots_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/robots")
}

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/urdf")
        .join(name)
}

fn reference(robot: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(robots_dir().join(format!("{robot}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn load_robot(robot: &str) -> Model {
    load_file(
        robots_dir().join(format!("{robot}.urdf")),
        &ModelOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

fn assert_vec(actual: &Vector3<f64>, expected: Vector3<f64>, tol: f64, what: &str) {
    assert!(
        (actual - expected).amax() <= tol,
        "{what}: {actual:?} != {expected:?}"
    );
}

fn assert_mat(actual: &Matrix3<f64>, expected: Matrix3<f64>, tol: f64, what: &str) {
    assert!(
        (actual - expected).amax() <= tol,
        "{what}: {actual:?} != {expected:?}"
    );
}

fn names(model: &Model) -> Vec<&str> {
    model.joints.iter().map(|j| j.name.as_str()).collect()
}

// ---------------------------------------------------------------------------------------------
// Reference robots

#[test]
fn reference_robots_have_the_reference_joints_in_the_reference_order() {
    for robot in ROBOTS {
        let model = load_robot(robot);
        let json = reference(robot);
        let expected: Vec<&str> = json["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap())
            .collect();
        assert_eq!(model.dof(), expected.len(), "{robot}");
        let ours: HashSet<&str> = names(&model).into_iter().collect();
        assert_eq!(ours, expected.iter().copied().collect(), "{robot}");
        // The default depth-first order, siblings by name, is Pinocchio's order.
        assert_eq!(names(&model), expected, "{robot}");
        let types: Vec<&str> = json["joint_types"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap())
            .collect();
        for (joint, ty) in model.joints.iter().zip(types) {
            let kind = joint.kind.urdf_name();
            assert_eq!(kind, ty, "{robot} {}", joint.name);
        }
    }
}

#[test]
fn reference_robots_are_well_formed() {
    for robot in ROBOTS {
        let model = load_robot(robot);
        let urdf = urdf_rs::read_file(robots_dir().join(format!("{robot}.urdf"))).unwrap();
        assert_eq!(model.frames.len(), urdf.links.len(), "{robot}");
        assert_eq!(model.bodies.len(), model.dof());
        for (i, joint) in model.joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                assert!(p < i, "{robot}: parent after child");
            }
            assert!((joint.axis.norm() - 1.0).abs() < 1e-15);
        }
        // Each body weighs the sum of its merged links (read independently with urdf-rs), and
        // the bodies together weigh every link not welded to the root.
        let mass = |name: &str| {
            let link = urdf.links.iter().find(|l| l.name == name).unwrap();
            link.inertial.mass.value
        };
        let mut merged = 0;
        for body in &model.bodies {
            assert_eq!(body.merged_links[0], body.name);
            let sum: f64 = body.merged_links.iter().map(|l| mass(l)).sum();
            assert!(
                (body.mass - sum).abs() <= 1e-12 * sum.max(1.0),
                "{robot} {}",
                body.name
            );
            merged += body.merged_links.len();
        }
        let welded_to_root: Vec<&str> = model
            .frames
            .iter()
            .filter(|f| f.body.is_none())
            .map(|f| f.name.as_str())
            .collect();
        assert!(welded_to_root.contains(&model.root.as_str()));
        assert_eq!(merged + welded_to_root.len(), urdf.links.len(), "{robot}");
        let total: f64 = urdf
            .links
            .iter()
            .map(|l| l.inertial.mass.value)
            .sum::<f64>()
            - welded_to_root.iter().map(|l| mass(l)).sum::<f64>();
        let bodies: f64 = model.bodies.iter().map(|b| b.mass).sum();
        assert!((bodies - total).abs() <= 1e-12 * total, "{robot}");
    }
}

/// Pose and velocity of a body frame in the world.
struct BodyState {
    rotation: Matrix3<f64>,
    position: Vector3<f64>,
    angular: Vector3<f64>,
    /// Velocity of the body-frame origin.
    linear: Vector3<f64>,
}

/// Forward kinematics and velocities, written independently of the code under test.
fn body_states(model: &Model, q: &[f64], qd: &[f64]) -> Vec<BodyState> {
    let mut states: Vec<BodyState> = Vec::new();
    for (i, joint) in model.joints.iter().enumerate() {
        let (r0, p0, w0, v0) = match joint.parent {
            Some(p) => {
                let s = &states[p];
                (s.rotation, s.position, s.angular, s.linear)
            }
            None => (
                Matrix3::identity(),
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::zeros(),
            ),
        };
        let r_joint = r0 * joint.origin.rotation;
        let p_joint = p0 + r0 * joint.origin.translation;
        let axis = r_joint * joint.axis;
        let v_joint = v0 + w0.cross(&(p_joint - p0));
        states.push(if joint.kind.is_revolute() {
            let turn = Rotation3::from_axis_angle(&Unit::new_normalize(joint.axis), q[i]);
            BodyState {
                rotation: r_joint * turn.matrix(),
                position: p_joint,
                angular: w0 + axis * qd[i],
                linear: v_joint,
            }
        } else {
            BodyState {
                rotation: r_joint,
                position: p_joint + axis * q[i],
                angular: w0,
                linear: v_joint + w0.cross(&(axis * q[i])) + axis * qd[i],
            }
        });
    }
    states
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Frame poses, potential and kinetic energies at every reference sample: checks origins,
/// axes, frame placements, merged masses, centres of mass and inertias against Pinocchio.
#[test]
fn reference_robots_match_pinocchio_kinematics_and_energies() {
    for robot in ROBOTS {
        let model = load_robot(robot);
        let json = reference(robot);
        assert_eq!(floats(&json["gravity"]), model.gravity.as_slice());
        for (k, sample) in json["samples"].as_array().unwrap().iter().enumerate() {
            let q = floats(&sample["q"]);
            let qd = floats(&sample["qd"]);
            let states = body_states(&model, &q, &qd);
            let mut potential = 0.0;
            let mut kinetic = 0.0;
            for (body, s) in model.bodies.iter().zip(&states) {
                let com = s.position + s.rotation * body.com;
                potential -= body.mass * model.gravity.dot(&com);
                let v_com = s.linear + s.angular.cross(&(com - s.position));
                let inertia = s.rotation * body.inertia * s.rotation.transpose();
                kinetic += 0.5 * body.mass * v_com.norm_squared()
                    + 0.5 * s.angular.dot(&(inertia * s.angular));
            }
            let what = format!("{robot} sample {k}");
            let expected_pe = sample["potential_energy"].as_f64().unwrap();
            let expected_ke = sample["kinetic_energy"].as_f64().unwrap();
            assert!(
                (potential - expected_pe).abs() <= 1e-9 * (1.0 + expected_pe.abs()),
                "{what}: potential {potential} != {expected_pe}"
            );
            assert!(
                (kinetic - expected_ke).abs() <= 1e-9 * (1.0 + expected_ke.abs()),
                "{what}: kinetic {kinetic} != {expected_ke}"
            );
            for frame in &model.frames {
                let world = match frame.body {
                    Some(b) => Transform {
                        rotation: states[b].rotation,
                        translation: states[b].position,
                    }
                    .compose(&frame.placement),
                    None => frame.placement.clone(),
                };
                let expected = &sample["frames"][&frame.name];
                let position = floats(&expected["position"]);
                assert_vec(
                    &world.translation,
                    Vector3::from_column_slice(&position),
                    1e-9,
                    &format!("{what}: frame {} position", frame.name),
                );
                let rows: Vec<Vec<f64>> = expected["rotation"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(floats)
                    .collect();
                let rotation = Matrix3::from_fn(|r, c| rows[r][c]);
                assert_mat(
                    &world.rotation,
                    rotation,
                    1e-9,
                    &format!("{what}: frame {} rotation", frame.name),
                );
            }
        }
    }
}

#[test]
fn allegro_loads_as_its_impossible_fingertips_merge_into_possible_bodies() {
    // The fingertip links alone break the triangle inequality by 11 %; each is welded to a
    // finger link, and the merged bodies are possible.
    let path = robots_dir().join("allegro_right_hand.urdf");
    let model = load_file(&path, &ModelOptions::default()).unwrap();
    let tip = model.bodies.iter().find(|b| b.name == "link_3.0").unwrap();
    assert_eq!(tip.merged_links, ["link_3.0", "link_3.0_tip"]);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

// ---------------------------------------------------------------------------------------------
// Handmade robot: merging by hand

/// Rotation of 90 degrees about x, exactly.
fn rx90() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0)
}

/// `m (|d|^2 E - d d^T)`, the parallel-axis term.
fn steiner(m: f64, d: Vector3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * m
}

fn handmade(options: &ModelOptions) -> Model {
    load_file(fixture("handmade.urdf"), options).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn handmade_tree_and_order() {
    let model = handmade(&ModelOptions::default());
    assert_eq!(model.name, "handmade");
    assert_eq!(model.root, "base");
    assert_eq!(model.gravity, Vector3::new(0.0, 0.0, -9.81));
    // Depth first; under `mid`, "mid_to_tool" (leading to finger_joint) sorts before "slide".
    assert_eq!(names(&model), ["j1", "finger_joint", "slide"]);
    let parents: Vec<_> = model.joints.iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(0)]);
    let kinds: Vec<_> = model.joints.iter().map(|j| j.kind).collect();
    assert_eq!(
        kinds,
        [
            JointKind::Revolute,
            JointKind::Continuous,
            JointKind::Prismatic
        ]
    );
    let merged: Vec<_> = model
        .bodies
        .iter()
        .map(|b| b.merged_links.clone())
        .collect();
    assert_eq!(
        merged,
        [
            vec!["link1", "mid", "tool"],
            vec!["finger"],
            vec!["link2", "sensor"]
        ]
    );
    let frames: Vec<_> = model
        .frames
        .iter()
        .map(|f| (f.name.as_str(), f.body))
        .collect();
    assert_eq!(
        frames,
        [
            ("base", None),
            ("plate", None),
            ("link1", Some(0)),
            ("mid", Some(0)),
            ("link2", Some(2)),
            ("sensor", Some(2)),
            ("tool", Some(0)),
            ("finger", Some(1)),
        ]
    );
    assert_eq!(model.path_to_root(2), [0, 2]);
    assert!(!model.bodies.iter().any(|b| b.symbolic));
    assert!(!model.joints.iter().any(|j| j.symbolic_origin));
}

#[test]
fn handmade_joint_origins_fold_in_fixed_joints() {
    let model = handmade(&ModelOptions::default());
    let tol = 1e-15;
    // j1: plate (0 0 0.1 above the root) then the joint's own 0 0 0.2.
    let j1 = &model.joints[0];
    assert_mat(&j1.origin.rotation, Matrix3::identity(), tol, "j1 rotation");
    assert_vec(
        &j1.origin.translation,
        Vector3::new(0.0, 0.0, 0.3),
        tol,
        "j1",
    );
    assert_eq!(j1.axis, Vector3::new(0.0, 0.0, 1.0));
    // finger_joint: tool sits at (0.5, 0, 0) + Rx90 (0, 0, 0.3) = (0.5, -0.3, 0) in link1,
    // rotated by Rx90; then the joint's (0.1, 0, 0) rotated by Rx90 is (0.1, 0, 0).
    let finger = &model.joints[1];
    assert_mat(&finger.origin.rotation, rx90(), tol, "finger rotation");
    assert_vec(
        &finger.origin.translation,
        Vector3::new(0.6, -0.3, 0.0),
        tol,
        "finger",
    );
    assert_eq!(finger.axis, Vector3::new(1.0, 0.0, 0.0)); // default axis
                                                          // slide: mid at (0.5, 0, 0) rotated by Rx90; Rx90 (0, 0.1, 0) = (0, 0, 0.1).
    let slide = &model.joints[2];
    assert_mat(&slide.origin.rotation, rx90(), tol, "slide rotation");
    assert_vec(
        &slide.origin.translation,
        Vector3::new(0.5, 0.0, 0.1),
        tol,
        "slide",
    );
    assert_eq!(slide.axis, Vector3::new(0.0, 0.0, 1.0)); // "0 0 2" normalized
                                                         // Frames.
    let frame = |name: &str| model.frames.iter().find(|f| f.name == name).unwrap();
    assert_vec(
        &frame("plate").placement.translation,
        Vector3::new(0.0, 0.0, 0.1),
        tol,
        "plate",
    );
    assert_eq!(frame("base").placement, Transform::identity());
    assert_eq!(frame("link1").placement, Transform::identity());
    assert_mat(&frame("tool").placement.rotation, rx90(), tol, "tool frame");
    assert_vec(
        &frame("tool").placement.translation,
        Vector3::new(0.5, -0.3, 0.0),
        tol,
        "tool",
    );
    assert_vec(
        &frame("sensor").placement.translation,
        Vector3::new(0.0, 0.0, 0.2),
        tol,
        "sensor",
    );
}

#[test]
fn handmade_limits_dynamics_and_mimic_are_kept() {
    let model = handmade(&ModelOptions::default());
    let [j1, finger, slide] = &model.joints[..] else {
        panic!()
    };
    assert_eq!(
        j1.limits,
        Some(Limits {
            lower: -2.0,
            upper: 2.5,
            effort: 10.0,
            velocity: 3.0
        })
    );
    assert_eq!((j1.damping, j1.friction), (0.5, 0.25));
    assert_eq!(j1.mimic, None);
    assert_eq!(finger.limits, None);
    assert_eq!((finger.damping, finger.friction), (0.0, 0.0));
    assert_eq!(
        finger.mimic,
        Some(Mimic {
            joint: "slide".into(),
            multiplier: 2.0,
            offset: 0.1
        })
    );
    assert_eq!(slide.limits.as_ref().map(|l| l.upper), Some(0.3));
}

#[test]
fn handmade_merged_inertias_equal_hand_computation() {
    let model = handmade(&ModelOptions::default());
    let tol = 1e-15;

    // Body 0 = link1 + mid + tool, in the link1 frame.
    // link1: m 1, com (0.1, 0, 0); inertial yaw 90 deg: Rz90 I Rz90^T swaps xx and yy and
    // negates xy.
    let (m1, c1) = (1.0, Vector3::new(0.1, 0.0, 0.0));
    let i1 = Matrix3::new(0.02, -0.001, 0.0, -0.001, 0.01, 0.0, 0.0, 0.0, 0.03);
    // mid: placed at (0.5, 0, 0) with roll 90 deg (y -> z, z -> -y); com Rx90 (0, 0.2, 0) =
    // (0, 0, 0.2) from there; Rx90 diag(0.04, 0.05, 0.06) Rx90^T swaps yy and zz.
    let (m2, c2) = (2.0, Vector3::new(0.5, 0.0, 0.2));
    let i2 = Matrix3::from_diagonal(&Vector3::new(0.04, 0.06, 0.05));
    // tool: placed at (0.5, -0.3, 0) with Rx90; its inertial pitch 90 deg, so the total
    // rotation Rx90 Ry90 maps x -> y, y -> z, z -> x: diag(0.001, 0.002, 0.003) becomes
    // diag(0.003, 0.001, 0.002).
    let (m3, c3) = (0.5, Vector3::new(0.5, -0.3, 0.0));
    let i3 = Matrix3::from_diagonal(&Vector3::new(0.003, 0.001, 0.002));

    let mass = m1 + m2 + m3; // 3.5
    let com = Vector3::new(
        (1.0 * 0.1 + 2.0 * 0.5 + 0.5 * 0.5) / 3.5,
        (0.5 * -0.3) / 3.5,
        (2.0 * 0.2) / 3.5,
    );
    let inertia =
        i1 + i2 + i3 + steiner(m1, c1 - com) + steiner(m2, c2 - com) + steiner(m3, c3 - com);
    let body = &model.bodies[0];
    assert_eq!(body.name, "link1");
    assert!((body.mass - 3.5).abs() < tol);
    assert_eq!(mass, 3.5);
    assert_vec(&body.com, com, tol, "link1 com");
    assert_mat(&body.inertia, inertia, 1e-15, "link1 inertia");
    // One entry fully by hand: Ixx = 0.02 + 0.04 + 0.003
    //   + sum m (dy^2 + dz^2) with com = (1.35, -0.15, 0.4) / 3.5.
    let (cy, cz) = (-0.15 / 3.5, 0.4 / 3.5);
    let ixx = 0.063
        + 1.0 * (cy * cy + cz * cz)
        + 2.0 * (cy * cy + (0.2 - cz) * (0.2 - cz))
        + 0.5 * ((-0.3 - cy) * (-0.3 - cy) + cz * cz);
    assert!((body.inertia[(0, 0)] - ixx).abs() < 1e-15);
    assert_eq!(body.inertia, body.inertia.transpose());

    // Body 1 = finger alone.
    let finger = &model.bodies[1];
    assert_eq!(finger.mass, 0.2);
    assert_eq!(finger.com, Vector3::new(0.05, 0.0, 0.0));
    assert_eq!(
        finger.inertia,
        Matrix3::from_diagonal(&Vector3::new(1e-4, 2e-4, 2e-4))
    );

    // Body 2 = link2 + the massless sensor: unchanged by the merge.
    let link2 = &model.bodies[2];
    assert_eq!(link2.mass, 0.8);
    assert_eq!(link2.com, Vector3::new(0.0, 0.0, 0.05));
    assert_eq!(
        link2.inertia,
        Matrix3::from_diagonal(&Vector3::new(0.002, 0.002, 0.001))
    );

    // Root-welded base and plate count for nothing.
    let total: f64 = model.bodies.iter().map(|b| b.mass).sum();
    assert!((total - (3.5 + 0.2 + 0.8)).abs() < tol);
}

#[test]
fn explicit_joint_order_renumbers_bodies_and_frames() {
    let options = ModelOptions {
        joint_order: Some(vec!["j1".into(), "slide".into(), "finger_joint".into()]),
        ..ModelOptions::default()
    };
    let model = handmade(&options);
    assert_eq!(names(&model), ["j1", "slide", "finger_joint"]);
    let bodies: Vec<_> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(bodies, ["link1", "link2", "finger"]);
    let parents: Vec<_> = model.joints.iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(0)]);
    let frame = |name: &str| model.frames.iter().find(|f| f.name == name).unwrap().body;
    assert_eq!(frame("sensor"), Some(1));
    assert_eq!(frame("finger"), Some(2));
    assert_eq!(frame("tool"), Some(0));
    // Same bodies, same numbers.
    let default = handmade(&ModelOptions::default());
    assert_eq!(model.bodies[1], default.bodies[2]);
    assert_eq!(model.joints[2].origin, default.joints[1].origin);
}

#[test]
fn gravity_and_symbolic_options() {
    let options = ModelOptions {
        gravity: [0.0, -9.81, 0.0],
        symbolic: SymbolicParams::Links(vec!["tool".into(), "plate".into()]),
        ..ModelOptions::default()
    };
    let model = handmade(&options);
    assert_eq!(model.gravity, Vector3::new(0.0, -9.81, 0.0));
    // "tool" is merged into link1's body; "plate" is welded to the root: no effect.
    let symbolic: Vec<_> = model.bodies.iter().map(|b| b.symbolic).collect();
    assert_eq!(symbolic, [true, false, false]);
    let origins: Vec<_> = model.joints.iter().map(|j| j.symbolic_origin).collect();
    assert_eq!(origins, [true, false, false]);

    let model = handmade(&ModelOptions {
        symbolic: SymbolicParams::Links(vec!["sensor".into()]),
        ..ModelOptions::default()
    });
    let symbolic: Vec<_> = model.bodies.iter().map(|b| b.symbolic).collect();
    assert_eq!(symbolic, [false, false, true]);

    let model = handmade(&ModelOptions {
        symbolic: SymbolicParams::All,
        ..ModelOptions::default()
    });
    assert!(model.bodies.iter().all(|b| b.symbolic));
    assert!(model.joints.iter().all(|j| j.symbolic_origin));
}

// ---------------------------------------------------------------------------------------------
// Bad input: one test per case, asserting the variant and that the message names the culprit.

const FILE: &str = "bad.urdf";

const INERTIAL: &str = r#"<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#;

fn link(name: &str) -> String {
    format!(r#"<link name="{name}">{INERTIAL}</link>"#)
}

fn joint(name: &str, kind: &str, parent: &str, child: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><axis xyz="0 0 1"/></joint>"#
    )
}

fn robot(parts: &[String]) -> String {
    format!(r#"<robot name="test">{}</robot>"#, parts.concat())
}

/// A valid one-joint robot: `base` -j1 (revolute)- `l1`.
fn valid() -> Vec<String> {
    vec![
        link("base"),
        link("l1"),
        joint("j1", "revolute", "base", "l1"),
    ]
}

fn load(text: &str) -> Result<Model, ModelError> {
    load_str(text, FILE, &ModelOptions::default())
}

/// Loads `text`, expecting an error whose message names the file and every culprit.
fn error(text: &str, options: &ModelOptions, culprits: &[&str]) -> ModelError {
    let err = match load_str(text, FILE, options) {
        Ok(_) => panic!("loaded: {text}"),
        Err(e) => e,
    };
    let message = err.to_string();
    assert!(message.starts_with(FILE), "{message}");
    for culprit in culprits {
        assert!(message.contains(culprit), "`{culprit}` not in: {message}");
    }
    err
}

fn bad(text: &str, culprits: &[&str]) -> ModelError {
    error(text, &ModelOptions::default(), culprits)
}

#[test]
fn valid_template_loads() {
    let model = load(&robot(&valid())).unwrap();
    assert_eq!(model.dof(), 1);
}

#[test]
fn error_unreadable_file() {
    let path = fixture("does_not_exist.urdf");
    let err = load_file(&path, &ModelOptions::default()).unwrap_err();
    assert!(matches!(err, ModelError::Io { .. }), "{err}");
    assert!(err.to_string().contains("does_not_exist.urdf"), "{err}");
    // A directory is unreadable too.
    let err = load_file(fixture(""), &ModelOptions::default()).unwrap_err();
    assert!(matches!(err, ModelError::Io { .. }), "{err}");
}

#[test]
fn error_malformed_xml() {
    for text in [
        "",
        "not xml",
        r#"<robot name="test"><link name="a"></robot>"#,
        r#"<robot name="test"><link name="a"/><joint name="j" type="hinge"><parent link="a"/><child link="a"/></joint></robot>"#,
        r#"<robot name="test"><link/></robot>"#,
        r#"<robot name="test"><link name="a"><inertial><mass value="heavy"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>"#,
    ] {
        let err = bad(text, &[]);
        assert!(matches!(err, ModelError::Format { .. }), "{err}");
    }
}

#[test]
fn error_nesting_too_deep_is_refused_without_overflowing_the_stack() {
    let depth = 100_000;
    let mut parts = valid();
    parts.push(format!(
        "{}{}",
        "<gazebo>".repeat(depth),
        "</gazebo>".repeat(depth)
    ));
    let err = bad(&robot(&parts), &["nested"]);
    assert!(matches!(err, ModelError::Format { .. }), "{err}");
    // Moderate nesting of unknown elements is fine.
    let mut parts = valid();
    parts.push(format!(
        "{}{}",
        "<gazebo>".repeat(50),
        "</gazebo>".repeat(50)
    ));
    assert!(load(&robot(&parts)).is_ok());
}

#[test]
fn error_missing_parent_or_child_link() {
    let mut parts = valid();
    parts.push(joint("j2", "revolute", "nowhere", "l1"));
    let err = bad(&robot(&parts), &["`j2`", "`nowhere`", "parent"]);
    assert!(
        matches!(err, ModelError::MissingLink { role: "parent", .. }),
        "{err}"
    );

    let mut parts = valid();
    parts.push(joint("j2", "revolute", "l1", "ghost"));
    let err = bad(&robot(&parts), &["`j2`", "`ghost`", "child"]);
    assert!(
        matches!(err, ModelError::MissingLink { role: "child", .. }),
        "{err}"
    );
}

#[test]
fn error_link_with_two_parents() {
    let mut parts = valid();
    parts.push(link("l2"));
    parts.push(joint("j2", "revolute", "base", "l2"));
    parts.push(joint("j3", "revolute", "l1", "l2"));
    let err = bad(&robot(&parts), &["`l2`", "`j2`", "`j3`"]);
    assert!(matches!(err, ModelError::MultipleParents { .. }), "{err}");
}

#[test]
fn error_several_roots() {
    let mut parts = valid();
    parts.push(link("orphan"));
    let err = bad(&robot(&parts), &["`base`", "`orphan`"]);
    assert!(matches!(err, ModelError::MultipleRoots { .. }), "{err}");
}

#[test]
fn error_cycle() {
    // A cycle beside a proper tree.
    let mut parts = valid();
    parts.extend([link("a"), link("b"), link("c")]);
    parts.push(joint("ab", "revolute", "a", "b"));
    parts.push(joint("ba", "revolute", "b", "a"));
    parts.push(joint("bc", "revolute", "b", "c"));
    let err = bad(&robot(&parts), &["`a`", "`b`", "cycle"]);
    assert!(
        matches!(err, ModelError::Cycle { ref links, .. } if links.len() == 2),
        "{err}"
    );
    // Nothing but a cycle: no root at all.
    let parts = [
        link("a"),
        link("b"),
        joint("ab", "revolute", "a", "b"),
        joint("ba", "revolute", "b", "a"),
    ];
    let err = bad(&robot(&parts), &["`a`", "`b`", "cycle"]);
    assert!(matches!(err, ModelError::Cycle { .. }), "{err}");
    // A joint from a link to itself.
    let mut parts = valid();
    parts.push(link("self"));
    parts.push(joint("loop", "fixed", "self", "self"));
    let err = bad(&robot(&parts), &["`self`", "cycle"]);
    assert!(matches!(err, ModelError::Cycle { .. }), "{err}");
}

#[test]
fn error_duplicate_names() {
    let mut parts = valid();
    parts.push(link("l1"));
    let err = bad(&robot(&parts), &["`l1`"]);
    assert!(matches!(err, ModelError::DuplicateLink { .. }), "{err}");

    let mut parts = valid();
    parts.push(link("l2"));
    parts.push(joint("j1", "revolute", "l1", "l2"));
    let err = bad(&robot(&parts), &["`j1`"]);
    assert!(matches!(err, ModelError::DuplicateJoint { .. }), "{err}");
}

#[test]
fn error_empty_name() {
    let mut parts = valid();
    parts.push(link(""));
    let err = bad(&robot(&parts), &["link number 3"]);
    assert!(
        matches!(
            err,
            ModelError::EmptyName {
                element: "link",
                index: 3,
                ..
            }
        ),
        "{err}"
    );

    let mut parts = valid();
    parts.push(link("l2"));
    parts.push(joint("", "revolute", "l1", "l2"));
    let err = bad(&robot(&parts), &["joint number 2"]);
    assert!(
        matches!(
            err,
            ModelError::EmptyName {
                element: "joint",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn error_no_links() {
    let err = bad(r#"<robot name="test"></robot>"#, &["no links"]);
    assert!(matches!(err, ModelError::NoLinks { .. }), "{err}");
}

#[test]
fn error_zero_axis() {
    let text = robot(&valid()).replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 0"/>"#);
    let err = bad(&text, &["`j1`", "zero axis"]);
    assert!(matches!(err, ModelError::ZeroAxis { .. }), "{err}");
}

#[test]
fn error_non_finite_numbers() {
    let with_j1 = |extra: &str| {
        robot(&[
            link("base"),
            link("l1"),
            format!(
                r#"<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>{extra}</joint>"#
            ),
        ])
    };
    let with_l1 = |inertial: &str| {
        robot(&[
            link("base"),
            format!(r#"<link name="l1"><inertial>{inertial}</inertial></link>"#),
            joint("j1", "revolute", "base", "l1"),
        ])
    };
    let inertia = r#"<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>"#;
    let cases = [
        (with_j1(r#"<origin xyz="NaN 0 0"/>"#), "`j1`", "origin"),
        (with_j1(r#"<origin rpy="0 inf 0"/>"#), "`j1`", "origin"),
        (with_j1(r#"<axis xyz="0 0 nan"/>"#), "`j1`", "axis"),
        (with_j1(r#"<axis xyz="-inf 0 1"/>"#), "`j1`", "axis"),
        (
            with_j1(r#"<limit lower="NaN" upper="1" effort="1" velocity="1"/>"#),
            "`j1`",
            "limit",
        ),
        (with_j1(r#"<dynamics damping="NaN"/>"#), "`j1`", "damping"),
        (with_j1(r#"<dynamics friction="inf"/>"#), "`j1`", "friction"),
        (
            with_j1(r#"<mimic joint="j1" multiplier="NaN"/>"#),
            "`j1`",
            "mimic",
        ),
        (
            with_l1(&format!(r#"<mass value="NaN"/>{inertia}"#)),
            "`l1`",
            "mass",
        ),
        (
            with_l1(&format!(r#"<mass value="inf"/>{inertia}"#)),
            "`l1`",
            "mass",
        ),
        (
            with_l1(
                r#"<mass value="1"/><inertia ixx="inf" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>"#,
            ),
            "`l1`",
            "inertia",
        ),
        (
            with_l1(&format!(
                r#"<origin xyz="0 NaN 0"/><mass value="1"/>{inertia}"#
            )),
            "`l1`",
            "inertial origin",
        ),
    ];
    for (text, culprit, field) in cases {
        let err = bad(&text, &[culprit, field]);
        assert!(matches!(err, ModelError::NonFinite { .. }), "{err}");
    }
    // Infinite limits mean "unbounded" (URDF 1.2 semantics), not an error.
    let model = load(&with_j1(
        r#"<limit lower="-inf" upper="inf" effort="1" velocity="1"/>"#,
    ))
    .unwrap();
    assert_eq!(
        model.joints[0].limits.as_ref().unwrap().upper,
        f64::INFINITY
    );
    // Finite numbers so large that their composition would overflow.
    let far = r#"<origin xyz="1e308 0 0"/>"#;
    let text = robot(&[
        link("base"),
        link("l1"),
        link("a"),
        link("b"),
        joint("j1", "revolute", "base", "l1"),
        format!(
            r#"<joint name="fa" type="fixed">{far}<parent link="l1"/><child link="a"/></joint>"#
        ),
        format!(
            r#"<joint name="fb" type="fixed">{far}<parent link="a"/><child link="b"/></joint>"#
        ),
    ]);
    let err = bad(&text, &["joint `fa`", "origin holds 1e308"]);
    assert!(matches!(err, ModelError::OutOfRange { .. }), "{err}");
    // A non-finite gravity option.
    let options = ModelOptions {
        gravity: [0.0, 0.0, f64::NAN],
        ..ModelOptions::default()
    };
    let err = error(&robot(&valid()), &options, &["gravity"]);
    assert!(matches!(err, ModelError::NonFinite { .. }), "{err}");
}

#[test]
fn error_negative_mass() {
    let text = robot(&valid()).replacen(r#"<mass value="1"/>"#, r#"<mass value="-1"/>"#, 2);
    // The moving body's is an error; base's, welded to the world, only a warning.
    let err = bad(&text, &["`l1`", "-1"]);
    assert!(matches!(err, ModelError::NegativeMass { .. }), "{err}");
    let (_, warnings) = eomgen::urdf::load_str_with_warnings(&text, FILE, &Default::default());
    assert!(
        matches!(&warnings[..], [ModelWarning::WeldedInertia { link, .. }] if link == "base"),
        "{warnings:?}"
    );
    let base_only = robot(&valid()).replacen(r#"<mass value="1"/>"#, r#"<mass value="-1"/>"#, 1);
    let model = load(&base_only).unwrap();
    let message = model.warnings[0].to_string();
    assert!(
        message.contains("`base` is welded to the world") && message.contains("negative (-1)"),
        "{message}"
    );
}

#[test]
fn error_inertia_not_positive_semi_definite() {
    // Principal moments -1, 1, 3.
    let l1 = r#"<link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="2" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#;
    let text = robot(&[
        link("base"),
        l1.into(),
        joint("j1", "revolute", "base", "l1"),
    ]);
    let err = bad(&text, &["`l1`", "positive semi-definite"]);
    assert!(matches!(err, ModelError::InvalidInertia { .. }), "{err}");
    // Negative principal moment on the diagonal.
    let text = text.replace(r#"ixx="1" ixy="2""#, r#"ixx="-0.1" ixy="0""#);
    let err = bad(&text, &["`l1`"]);
    assert!(matches!(err, ModelError::InvalidInertia { .. }), "{err}");
}

#[test]
fn error_inertia_breaking_the_triangle_inequality_unless_repaired() {
    // 1 + 1 < 2.5: impossible.
    let l1 = r#"<link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="2.5"/></inertial></link>"#;
    let text = robot(&[
        link("base"),
        l1.into(),
        joint("j1", "revolute", "base", "l1"),
    ]);
    let err = bad(
        &text,
        &["`l1`", "triangle inequality 2.5 <= 1 + 1", "repair_inertia"],
    );
    assert!(matches!(err, ModelError::InvalidInertia { .. }), "{err}");
    // Equality (a flat plate) is fine.
    let plate = text.replace(r#"izz="2.5""#, r#"izz="2""#);
    assert!(load(&plate).is_ok());
    // Repaired: the principal moments become their mean, and a warning says so.
    let repair = ModelOptions {
        repair_inertia: true,
        ..ModelOptions::default()
    };
    let model = load_str(&text, FILE, &repair).unwrap();
    assert_eq!(model.bodies[0].inertia, Matrix3::identity() * 1.5);
    match &model.warnings[..] {
        [w @ ModelWarning::InertiaRepaired {
            link,
            before,
            after,
            ..
        }] => {
            assert_eq!(
                (link.as_str(), *before, *after),
                ("l1", [1.0, 1.0, 2.5], [1.5; 3])
            );
            let message = w.to_string();
            assert!(
                message.contains("triangle inequality") && message.contains("1.5, 1.5, 1.5"),
                "{message}"
            );
        }
        other => panic!("{other:?}"),
    }
    // A possible inertia is left alone.
    let model = load_str(&plate, FILE, &repair).unwrap();
    assert!(model.warnings.is_empty());
    assert_eq!(model.bodies[0].inertia[(2, 2)], 2.0);
}

#[test]
fn inertia_is_checked_on_merged_bodies_with_an_absolute_tolerance() {
    // Each of l1's two halves breaks the triangle inequality (0.03 > 0.01 + 0.01); welded
    // together 0.2 m apart along z, they do not (0.06 <= 0.04 + 0.04).
    let half = |name: &str, z: f64| {
        format!(
            r#"<link name="{name}"><inertial><origin xyz="0 0 {z}"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.03"/></inertial></link>"#
        )
    };
    let text = robot(&[
        link("base"),
        half("l1", 0.1),
        half("l1b", -0.1),
        joint("j1", "revolute", "base", "l1"),
        r#"<joint name="weld" type="fixed"><parent link="l1"/><child link="l1b"/></joint>"#.into(),
    ]);
    let model = load(&text).unwrap();
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    // Without its other half, l1 is refused.
    let alone = robot(&[
        link("base"),
        half("l1", 0.1),
        joint("j1", "revolute", "base", "l1"),
    ]);
    bad(&alone, &["`l1`", "triangle"]);
    // Rounding noise on a point mass passes (a relative tolerance alone would refuse it).
    let noisy = r#"<link name="l1"><inertial><origin xyz="0.5 0.5 0.5"/><mass value="1"/><inertia ixx="1e-20" ixy="0" ixz="0" iyy="-1e-20" iyz="0" izz="1e-35"/></inertial></link>"#;
    let text = robot(&[
        link("base"),
        noisy.into(),
        joint("j1", "revolute", "base", "l1"),
    ]);
    load(&text).unwrap();
}

#[test]
fn error_moving_joint_with_nothing_to_move() {
    let point_mass = |name: &str, x: f64, z: f64| {
        format!(
            r#"<link name="{name}"><inertial><origin xyz="{x} 0 {z}"/><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>"#
        )
    };
    let rotational_only = r#"<link name="l1"><inertial><mass value="0"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#;
    let singular = [
        // A massless child link.
        robot(&[
            link("base"),
            "<link name=\"l1\"/>".into(),
            joint("j1", "revolute", "base", "l1"),
        ]),
        robot(&[
            link("base"),
            "<link name=\"l1\"/>".into(),
            joint("j1", "prismatic", "base", "l1"),
        ]),
        // A prismatic joint needs mass; rotational inertia alone does not resist translation.
        robot(&[
            link("base"),
            rotational_only.into(),
            joint("j1", "prismatic", "base", "l1"),
        ]),
        // A point mass on the axis of a revolute joint (z).
        robot(&[
            link("base"),
            point_mass("l1", 0.0, 0.5),
            joint("j1", "continuous", "base", "l1"),
        ]),
    ];
    for text in singular {
        let err = bad(&text, &["`j1`"]);
        assert!(matches!(err, ModelError::MasslessSubtree { .. }), "{err}");
    }
    let fine = [
        // A point mass off the axis.
        robot(&[
            link("base"),
            point_mass("l1", 0.5, 0.0),
            joint("j1", "revolute", "base", "l1"),
        ]),
        // Rotational inertia alone for a revolute joint.
        robot(&[
            link("base"),
            rotational_only.into(),
            joint("j1", "revolute", "base", "l1"),
        ]),
        // A massless child carrying a massive grandchild, through a moving or a fixed joint.
        robot(&[
            link("base"),
            "<link name=\"l1\"/>".into(),
            link("l2"),
            joint("j1", "revolute", "base", "l1"),
            joint("j2", "revolute", "l1", "l2"),
        ]),
        robot(&[
            link("base"),
            "<link name=\"l1\"/>".into(),
            link("l2"),
            joint("j1", "prismatic", "base", "l1"),
            joint("f", "fixed", "l1", "l2"),
        ]),
    ];
    for text in fine {
        load(&text).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn error_unsupported_joint_types() {
    let mut parts = valid();
    parts.push(link("l2"));
    parts.push(joint("free", "spherical", "l1", "l2"));
    let err = bad(&robot(&parts), &["`free`", "spherical"]);
    assert!(matches!(err, ModelError::UnsupportedJoint { .. }), "{err}");
}

#[test]
fn planar_and_floating_joints_load_with_their_coordinates() {
    for (kind, names, nq) in [
        ("planar", vec!["j1", "free.x", "free.y", "free.theta"], 4),
        (
            "floating",
            vec![
                "j1", "free.vx", "free.vy", "free.vz", "free.wx", "free.wy", "free.wz",
            ],
            8,
        ),
    ] {
        let mut parts = valid();
        parts.push(link("l2"));
        parts.push(joint("free", kind, "l1", "l2"));
        let model = load(&robot(&parts)).unwrap();
        assert_eq!(model.velocity_names(), names, "{kind}");
        assert_eq!((model.nq(), model.nv()), (nq, names.len()), "{kind}");
        assert_eq!(model.velocities_are_rates(), kind == "planar");
        // The link frame moves with the joint's last step.
        let l2 = model.frames.iter().find(|f| f.name == "l2").unwrap();
        assert_eq!(l2.body, Some(model.dof() - 1));
        // The massless bodies between a planar joint's steps are named after their steps, not
        // after the child link they do not hold (every body's name, and so every identified
        // parameter's, is unique).
        let bodies: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
        let expected = match kind {
            "planar" => vec!["l1", "free.x", "free.y", "l2"],
            _ => vec!["l1", "l2"],
        };
        assert_eq!(bodies, expected, "{kind}");
        assert!(model.bodies[1..model.dof() - 1]
            .iter()
            .all(|b| b.merged_links.is_empty() && b.mass == 0.0));
    }
}

#[test]
fn error_floating_joint_with_an_unsupported_option() {
    let mut parts = valid();
    parts.push(link("l2"));
    parts.push(joint("free", "floating", "l1", "l2"));
    let options = ModelOptions {
        passive_joints: vec!["j1".into()],
        ..ModelOptions::default()
    };
    let err = error(&robot(&parts), &options, &["`free`", "passive_joints"]);
    assert!(
        matches!(err, ModelError::UnsupportedJointUse { .. }),
        "{err}"
    );
}

#[test]
fn error_no_moving_joint() {
    let only_fixed = robot(&[link("base"), link("l1"), joint("f", "fixed", "base", "l1")]);
    let single_link = robot(&[link("base")]);
    for text in [only_fixed, single_link] {
        let err = bad(&text, &["no moving joint"]);
        assert!(matches!(err, ModelError::NoMovingJoint { .. }), "{err}");
    }
}

#[test]
fn error_invalid_joint_order() {
    let text = std::fs::read_to_string(fixture("handmade.urdf")).unwrap();
    let cases: [(&[&str], &str, &str); 5] = [
        (&["j1", "slide"], "finger_joint", "missing"),
        (
            &["j1", "slide", "finger_joint", "nope"],
            "nope",
            "does not exist",
        ),
        (
            &["j1", "slide", "j1", "finger_joint"],
            "j1",
            "more than once",
        ),
        (
            &["j1", "mid_to_tool", "slide", "finger_joint"],
            "mid_to_tool",
            "fixed",
        ),
        (
            &["slide", "j1", "finger_joint"],
            "slide",
            "parent joint `j1`",
        ),
    ];
    for (order, culprit, reason) in cases {
        let options = ModelOptions {
            joint_order: Some(order.iter().map(|s| s.to_string()).collect()),
            ..ModelOptions::default()
        };
        let err = error(&text, &options, &[&format!("`{culprit}`"), reason]);
        assert!(matches!(err, ModelError::InvalidJointOrder { .. }), "{err}");
    }
}

#[test]
fn error_unknown_symbolic_link() {
    let options = ModelOptions {
        symbolic: SymbolicParams::Links(vec!["l1".into(), "wing".into()]),
        ..ModelOptions::default()
    };
    let err = error(&robot(&valid()), &options, &["`wing`"]);
    assert!(
        matches!(err, ModelError::UnknownSymbolicLink { .. }),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// No panic on mutated text

const TOKENS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-0",
    "0",
    "-1",
    "",
    " ",
    "<",
    ">",
    "/>",
    "</",
    "\"",
    "'",
    "=",
    "&",
    "&amp;",
    "&#0;",
    "&#x110000;",
    "<!--",
    "-->",
    "<![CDATA[",
    "]]>",
    "<?x?>",
    "<!DOCTYPE r>",
    "xmlns:x=\"u\" ",
    "x:",
    "xml:",
    "é",
    "\u{0}",
    "name=\"\"",
    "<link name=\"a\"/>",
    "<joint name=\"j\" type=\"floating\"><parent link=\"a\"/><child link=\"b\"/></joint>",
    "<inertial><mass value=\"1\"/></inertial>",
    "type=\"fixed\"",
    "type=\"prismatic\"",
    "link=\"base\"",
    "link=\"link1\"",
    "version=\"1.2\" ",
    "quat_xyzw=\"0 0 0 0\" ",
    "<limit/>",
];

#[derive(Clone, Debug)]
enum Edit {
    Delete(prop::sample::Index, usize),
    Insert(prop::sample::Index, usize),
    Replace(prop::sample::Index, usize, usize),
    /// Replace the n-th number-looking word with a token.
    Number(prop::sample::Index, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    let at = any::<prop::sample::Index>();
    let token = 0..TOKENS.len();
    prop_oneof![
        (at.clone(), 1usize..40).prop_map(|(a, n)| Edit::Delete(a, n)),
        (at.clone(), token.clone()).prop_map(|(a, t)| Edit::Insert(a, t)),
        (at.clone(), 1usize..20, token.clone()).prop_map(|(a, n, t)| Edit::Replace(a, n, t)),
        (at, token).prop_map(|(a, t)| Edit::Number(a, t)),
    ]
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for e in edits {
        let len = bytes.len();
        let pos = |i: &prop::sample::Index| if len == 0 { 0 } else { i.index(len + 1) };
        match e {
            Edit::Delete(i, n) => {
                let start = pos(i);
                let end = (start + n).min(len);
                bytes.drain(start..end);
            }
            Edit::Insert(i, t) => {
                let at = pos(i);
                bytes.splice(at..at, TOKENS[*t].bytes());
            }
            Edit::Replace(i, n, t) => {
                let start = pos(i);
                let end = (start + n).min(len);
                bytes.splice(start..end, TOKENS[*t].bytes());
            }
            Edit::Number(i, t) => {
                let starts: Vec<usize> = (0..len)
                    .filter(|&k| {
                        bytes[k].is_ascii_digit()
                            && (k == 0 || !bytes[k - 1].is_ascii_alphanumeric())
                    })
                    .collect();
                if !starts.is_empty() {
                    let start = starts[i.index(starts.len())];
                    let end = (start..len)
                        .find(|&k| {
                            !(bytes[k].is_ascii_digit() || bytes[k] == b'.' || bytes[k] == b'e')
                        })
                        .unwrap_or(len);
                    bytes.splice(start..end, TOKENS[*t].bytes());
                }
            }
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

fn check_invariants(model: &Model) {
    assert!(model.dof() > 0);
    assert_eq!(model.bodies.len(), model.dof());
    for (i, joint) in model.joints.iter().enumerate() {
        assert!(joint.parent.is_none_or(|p| p < i));
        assert!((joint.axis.norm() - 1.0).abs() < 1e-12);
        assert!(joint.origin.rotation.iter().all(|x| x.is_finite()));
        assert!(joint.origin.translation.iter().all(|x| x.is_finite()));
    }
    for body in &model.bodies {
        assert!(body.mass.is_finite() && body.mass >= 0.0);
        assert!(body
            .com
            .iter()
            .chain(body.inertia.iter())
            .all(|x| x.is_finite()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn mutated_urdf_never_panics(
        robot in prop::sample::select(vec!["handmade", "double_pendulum"]),
        edits in prop::collection::vec(edit(), 1..6),
    ) {
        let mutated = mutate(robot, &edits);
        if let Ok(model) = load_str(&mutated, "mutated.urdf", &ModelOptions::default()) {
            check_invariants(&model);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The whole path, derivation and emission included (the fuzz target's in `fuzz/`).
    #[test]
    fn mutated_urdf_gives_code_or_an_error_naming_the_file(
        robot in prop::sample::select(vec!["handmade", "double_pendulum"]),
        edits in prop::collection::vec(edit(), 1..6),
    ) {
        let mutated = mutate(robot, &edits);
        match eomgen::Builder::from_urdf_str(&mutated, "mutated.urdf").generate() {
            Ok(source) => prop_assert!(source.starts_with("// @generated by eomgen")),
            Err(eomgen::Error::Emit(e)) => prop_assert!(false, "emission failed: {}", e),
            // `mutated.urdf: ...`, or `mutated.urdf:line:column: ...` for format errors.
            Err(e) => prop_assert!(e.to_string().starts_with("mutated.urdf:"), "{}", e),
        }
    }
}

fn mutate(robot: &str, edits: &[Edit]) -> String {
    let text = match robot {
        "handmade" => include_str!("urdf/handmade.urdf"),
        _ => include_str!("../../tests/robots/double_pendulum.urdf"),
    };
    apply(text, edits)
}
