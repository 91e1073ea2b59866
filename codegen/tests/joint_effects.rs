//! Joint effects in the derivation: rotor inertia (armature) on M's diagonal in every route,
//! joint friction from `<dynamics damping friction>` in inverse and forward dynamics, and a
//! missing `<inertial>` filled from `<collision>` primitives, with its warnings and errors.
//!
//! The fixture is `tests/fixtures/joint_effects.urdf` of the workspace (two joints, a link
//! without `<inertial>` but with a collision box, a mesh-only link); expected values are
//! computed by hand here.

#![allow(clippy::needless_range_loop)]

use std::path::PathBuf;

use eomgen::cas::{Id, Program, SymbolKind};
use eomgen::dynamics::Derivation;
use eomgen::model::{Model, ModelError, ModelOptions, ModelWarning};
use eomgen::urdf::{load_file, load_str};
use nalgebra::{Matrix3, Vector3};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace holds codegen/")
        .to_path_buf()
}

fn fixture() -> PathBuf {
    workspace().join("tests/fixtures/joint_effects.urdf")
}

/// The fixture with the upper arm filled at 1000 kg/m^3 (4 kg) and the given options.
fn options(f: impl FnOnce(&mut ModelOptions)) -> ModelOptions {
    let mut o = ModelOptions {
        inertia_from_collision: Some(1000.0),
        ..ModelOptions::default()
    };
    f(&mut o);
    o
}

fn load(o: &ModelOptions) -> Model {
    load_file(fixture(), o).unwrap_or_else(|e| panic!("{e}"))
}

fn load_err(o: &ModelOptions) -> String {
    match load_file(fixture(), o) {
        Ok(_) => panic!("loads, but should fail"),
        Err(e) => e.to_string(),
    }
}

/// A numeric state; `tau` feeds forward dynamics.
#[derive(Clone, Default)]
struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    tau: Vec<f64>,
}

fn eval(d: &Derivation, outputs: &[Id], s: &State) -> Vec<f64> {
    Program::new(&d.graph, outputs)
        .eval(|sym| match sym.kind {
            SymbolKind::Q(i) => s.q.get(i).copied(),
            SymbolKind::Qd(i) => s.qd.get(i).copied(),
            SymbolKind::Qdd(i) => s.qdd.get(i).copied(),
            SymbolKind::Tau(i) => s.tau.get(i).copied(),
            SymbolKind::Force(_) | SymbolKind::Param => None,
        })
        .expect("numeric model")
}

fn flat(m: &[Vec<Id>]) -> Vec<Id> {
    m.iter().flatten().copied().collect()
}

/// A few deterministic states, velocities of both signs and zero.
fn states(n: usize) -> Vec<State> {
    let mut x = 0.37_f64;
    let mut next = move || {
        x = (x * 7.13 + 0.291).fract();
        4.0 * x - 2.0
    };
    let mut out: Vec<State> = (0..6)
        .map(|_| State {
            q: (0..n).map(|_| next()).collect(),
            qd: (0..n).map(|_| next()).collect(),
            qdd: (0..n).map(|_| next()).collect(),
            tau: Vec::new(),
        })
        .collect();
    out[0].qd = vec![0.0; n];
    out
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

const ARMATURE: [(&str, f64); 2] = [("shoulder", 0.2), ("elbow", 0.05)];

fn with_armature(o: &mut ModelOptions) {
    o.armature = ARMATURE.iter().map(|(j, v)| (j.to_string(), *v)).collect();
}

#[test]
fn armature_adds_exactly_to_the_diagonal_on_every_route() {
    let plain = Derivation::new(&load(&options(|_| {})));
    let model = load(&options(with_armature));
    assert_eq!(model.joints[0].armature, 0.2);
    assert_eq!(model.joints[1].armature, 0.05);
    let armed = Derivation::new(&model);
    let quantities = |d: &Derivation| -> Vec<Id> {
        let mut v = flat(&d.mass_matrix);
        v.extend(flat(&d.recursive.mass_matrix));
        v.extend(flat(&d.fast.mass_matrix.1));
        v.extend(&d.tau);
        v.extend(&d.recursive.tau);
        v.extend([d.kinetic_energy, d.fast.kinetic_energy]);
        v
    };
    for s in states(2) {
        let a = eval(&armed, &quantities(&armed), &s);
        let p = eval(&plain, &quantities(&plain), &s);
        // Three mass matrices: the diagonal gains exactly Ia, nothing else changes.
        for route in 0..3 {
            for i in 0..2 {
                for j in 0..2 {
                    let k = route * 4 + i * 2 + j;
                    let extra = if i == j { ARMATURE[i].1 } else { 0.0 };
                    assert!(
                        (a[k] - p[k] - extra).abs() < 1e-14,
                        "route {route}, M{i}{j}: {} vs {} + {extra}",
                        a[k],
                        p[k]
                    );
                }
            }
        }
        // tau gains Ia qdd on both routes; T gains Ia qd^2 / 2 on both.
        for route in 0..2 {
            for i in 0..2 {
                let k = 12 + route * 2 + i;
                assert!((a[k] - p[k] - ARMATURE[i].1 * s.qdd[i]).abs() < 1e-12);
            }
        }
        let rotor: f64 = (0..2)
            .map(|i| 0.5 * ARMATURE[i].1 * s.qd[i] * s.qd[i])
            .sum();
        for k in [16, 17] {
            assert!((a[k] - p[k] - rotor).abs() < 1e-14, "kinetic energy");
        }
    }
}

#[test]
fn armature_on_a_prismatic_joint_of_a_branched_robot() {
    // handmade.urdf: a revolute, a prismatic and a revolute joint on two branches.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/urdf/handmade.urdf");
    let plain = Derivation::new(&load_file(&path, &ModelOptions::default()).unwrap());
    let o = ModelOptions {
        armature: vec![("slide".into(), 1.5), ("j1".into(), 0.25)],
        ..ModelOptions::default()
    };
    let model = load_file(&path, &o).unwrap();
    let armed = Derivation::new(&model);
    let slide = model.joints.iter().position(|j| j.name == "slide").unwrap();
    let j1 = model.joints.iter().position(|j| j.name == "j1").unwrap();
    let n = model.dof();
    for s in states(n) {
        let a = eval(&armed, &flat(&armed.recursive.mass_matrix), &s);
        let l = eval(&armed, &flat(&armed.mass_matrix), &s);
        let p = eval(&plain, &flat(&plain.mass_matrix), &s);
        for i in 0..n {
            for j in 0..n {
                let extra = match (i == j, i) {
                    (true, i) if i == slide => 1.5,
                    (true, i) if i == j1 => 0.25,
                    _ => 0.0,
                };
                let k = i * n + j;
                assert!((l[k] - p[k] - extra).abs() < 1e-13, "M{i}{j} Lagrangian");
                assert!((a[k] - l[k]).abs() < 1e-13, "M{i}{j} CRBA vs Lagrangian");
            }
        }
    }
}

/// `tau` by the Lagrangian route, by Newton-Euler, the emitted (fast) form and Lagrange's
/// equations from `L = T - V` (plus friction), and forward dynamics inverting it.
fn check_routes(model: &Model) -> f64 {
    let mut d = Derivation::new(model);
    let lagrange = d.lagrange_equations();
    let n = d.dof;
    let mut worst: f64 = 0.0;
    for mut s in states(n) {
        let mut outs = d.tau.clone();
        outs.extend(&d.recursive.tau);
        outs.extend(&d.fast.tau.1);
        outs.extend(&lagrange);
        let v = eval(&d, &outs, &s);
        for route in 1..4 {
            for i in 0..n {
                assert!(
                    close(v[route * n + i], v[i], 1e-12),
                    "route {route}, tau{i}: {} vs {}",
                    v[route * n + i],
                    v[i]
                );
            }
        }
        s.tau = v[..n].to_vec();
        let qdd = eval(&d, &d.fast.forward_dynamics, &s);
        for i in 0..n {
            worst = worst.max((qdd[i] - s.qdd[i]).abs());
        }
    }
    worst
}

#[test]
fn routes_agree_with_friction_and_armature() {
    for smoothing in [0.0, 0.05] {
        let model = load(&options(|o| {
            with_armature(o);
            o.friction = true;
            o.coulomb_smoothing = smoothing;
        }));
        let err = check_routes(&model);
        eprintln!("friction (smoothing {smoothing}) + armature: |forward(inverse(qdd)) - qdd| <= {err:.1e}");
        assert!(err < 1e-10, "round trip error {err}");
    }
}

#[test]
fn friction_term_matches_hand_computation() {
    // shoulder: damping 0.5, friction 0.2; elbow: damping 0.1, friction 0.05.
    let exact = Derivation::new(&load(&options(|o| o.friction = true)));
    let at = |d: &Derivation, qd: [f64; 2]| {
        let s = State {
            qd: qd.to_vec(),
            ..State::default()
        };
        eval(d, &d.friction, &s)
    };
    let cases = [
        ([1.0, -2.0], [0.5 + 0.2, -0.2 - 0.05]),
        ([-0.3, 0.0], [-0.15 - 0.2, 0.0]),
        ([0.0, 0.0], [0.0, 0.0]),
    ];
    for (qd, want) in cases {
        let got = at(&exact, qd);
        for i in 0..2 {
            assert!(
                close(got[i], want[i], 1e-15),
                "qd {qd:?}: {got:?} != {want:?}"
            );
        }
    }
    // Smoothed: s(v) = v / sqrt(v^2 + eps^2), eps = 0.1.
    let smooth = Derivation::new(&load(&options(|o| {
        o.friction = true;
        o.coulomb_smoothing = 0.1;
    })));
    let got = at(&smooth, [0.1, -0.2]);
    let want = [
        0.5 * 0.1 + 0.2 * 0.1 / 0.02_f64.sqrt(),
        0.1 * -0.2 + 0.05 * -0.2 / 0.05_f64.sqrt(),
    ];
    for i in 0..2 {
        assert!(close(got[i], want[i], 1e-15), "{got:?} != {want:?}");
    }
    // Far above eps the smoothed term approaches the exact one.
    let (fast, exact_fast) = (at(&smooth, [50.0, -50.0]), at(&exact, [50.0, -50.0]));
    assert!((fast[0] - exact_fast[0]).abs() < 0.2 * 2e-6);
    // Friction is part of tau but not of the bias.
    let s = State {
        q: vec![0.3, 0.4],
        qd: vec![1.0, -2.0],
        qdd: vec![0.0, 0.0],
        tau: vec![],
    };
    let mut outs = exact.tau.clone();
    outs.extend(&exact.bias);
    outs.extend(&exact.gravity);
    let v = eval(&exact, &outs, &s);
    for i in 0..2 {
        let f = [0.7, -0.25][i];
        assert!(close(v[i], v[2 + i] + v[4 + i] + f, 1e-14));
    }
}

#[test]
fn friction_is_left_out_unless_asked_for() {
    let model = load(&options(|_| {}));
    assert!(!model.include_friction);
    // The URDF's coefficients are kept all the same.
    assert_eq!(
        (model.joints[0].damping, model.joints[0].friction),
        (0.5, 0.2)
    );
    let d = Derivation::new(&model);
    assert!(d.friction.iter().all(|&f| d.graph.as_const(f) == Some(0.0)));
}

#[test]
fn invalid_armature_and_options_are_errors_naming_the_culprit() {
    let armature = |name: &str, v: f64| options(|o| o.armature = vec![(name.into(), v)]);
    let e = load_err(&armature("wrist", 0.1));
    assert!(e.contains("armature: joint `wrist` does not exist"), "{e}");
    let e = load_err(&armature("fore_to_camera", 0.1));
    assert!(e.contains("`fore_to_camera` is a fixed joint"), "{e}");
    let e = load_err(&armature("elbow", -0.1));
    assert!(e.contains("`elbow` has a negative value (-0.1)"), "{e}");
    let e = load_err(&armature("elbow", f64::NAN));
    assert!(e.contains("`elbow` has a non-finite value"), "{e}");
    assert!(matches!(
        load_file(fixture(), &armature("wrist", 0.1)),
        Err(ModelError::InvalidArmature { .. })
    ));
    for rho in [0.0, -1000.0, f64::NAN, f64::INFINITY] {
        let e = load_err(&options(|o| o.inertia_from_collision = Some(rho)));
        assert!(
            e.contains("option inertia_from_collision: the density must be positive"),
            "{e}"
        );
    }
    let e = load_err(&options(|o| o.coulomb_smoothing = -0.1));
    assert!(e.contains("option coulomb_smoothing"), "{e}");
    // Every message starts with the file.
    assert!(e.starts_with(&fixture().display().to_string()));
}

#[test]
fn armature_makes_a_massless_joint_invertible() {
    // Without its filled inertia, `upper` is massless but the shoulder still moves `fore`; a
    // massless leaf would be singular unless it has rotor inertia.
    let urdf = r#"<robot name="r"><link name="a"/><link name="b"/>
      <joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint></robot>"#;
    let e = load_str(urdf, "r.urdf", &ModelOptions::default()).unwrap_err();
    assert!(matches!(e, ModelError::MasslessSubtree { .. }), "{e}");
    let o = ModelOptions {
        armature: vec![("j".into(), 0.01)],
        ..ModelOptions::default()
    };
    let model = load_str(urdf, "r.urdf", &o).unwrap();
    let d = Derivation::new(&model);
    let m = eval(&d, &flat(&d.fast.mass_matrix.1), &states(1)[1]);
    assert_eq!(m, vec![0.01]);
}

#[test]
fn missing_inertia_is_filled_from_a_collision_box() {
    let model = load(&options(|_| {}));
    // upper: a 0.1 x 0.1 x 0.4 m box of 1000 kg/m^3 centred at z = 0.2.
    let upper = &model.bodies[0];
    assert_eq!(upper.name, "upper");
    let m = 1000.0 * 0.1 * 0.1 * 0.4;
    assert!(close(upper.mass, m, 1e-15), "{}", upper.mass);
    assert!((upper.com - Vector3::new(0.0, 0.0, 0.2)).norm() < 1e-15);
    let box_inertia = Matrix3::from_diagonal(&Vector3::new(
        m * (0.1 * 0.1 + 0.4 * 0.4) / 12.0,
        m * (0.1 * 0.1 + 0.4 * 0.4) / 12.0,
        m * (0.1 * 0.1 + 0.1 * 0.1) / 12.0,
    ));
    assert!((upper.inertia - box_inertia).amax() < 1e-15);
    // fore keeps its own <inertial> (its cylinder is not used); the mesh-only camera adds
    // nothing.
    let fore = &model.bodies[1];
    assert_eq!((fore.mass, fore.com), (1.0, Vector3::new(0.0, 0.0, 0.15)));
    assert_eq!(fore.merged_links, ["fore", "camera"]);
    // One warning per link that had none: the filled one and the mesh-only one, never the
    // root's.
    let file = fixture().display().to_string();
    assert_eq!(
        model.warnings,
        [
            ModelWarning::InertiaFromCollision {
                file: file.clone(),
                link: "upper".into(),
                mass: upper.mass,
                primitives: 1,
                density: 1000.0,
                ignored: vec![],
            },
            ModelWarning::NoCollisionPrimitive {
                file: file.clone(),
                link: "camera".into(),
                ignored: vec!["mesh".into()],
            },
        ]
    );
    let text: Vec<String> = model.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        text[0],
        format!(
            "{file}: link `upper` has no <inertial>: mass 4 kg, centre of mass and inertia \
             computed from 1 <collision> primitive(s) at a density of 1000 kg/m^3"
        )
    );
    assert!(
        text[1].contains("link `camera` has no <inertial>, and its <collision> geometry (mesh)")
            && text[1].ends_with("the link stays massless"),
        "{}",
        text[1]
    );
    // Without the option nothing is filled and nothing is said.
    let plain = load(&ModelOptions::default());
    assert_eq!(plain.bodies[0].mass, 0.0);
    assert!(plain.warnings.is_empty());
}

#[test]
fn filling_uses_every_primitive_and_names_what_it_ignores() {
    // A cylinder along x (rotated about y) and a sphere, plus a capsule and a mesh to ignore.
    let urdf = r#"<robot name="r"><link name="a"/>
      <link name="b">
        <collision><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
          <geometry><cylinder radius="0.05" length="0.4"/></geometry></collision>
        <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
        <collision><geometry><capsule radius="0.05" length="0.1"/></geometry></collision>
        <collision><geometry><mesh filename="b.stl"/></geometry></collision>
      </link>
      <joint name="j" type="continuous"><parent link="a"/><child link="b"/>
        <axis xyz="0 0 1"/></joint></robot>"#;
    let o = ModelOptions {
        inertia_from_collision: Some(2000.0),
        ..ModelOptions::default()
    };
    let model = load_str(urdf, "r.urdf", &o).unwrap();
    let pi = std::f64::consts::PI;
    let (mc, ms) = (2000.0 * pi * 0.0025 * 0.4, 2000.0 * 4.0 / 3.0 * pi * 0.001);
    let b = &model.bodies[0];
    assert!(close(b.mass, mc + ms, 1e-14));
    let cx = (mc * 0.2 + ms * 0.5) / (mc + ms);
    assert!((b.com - Vector3::new(cx, 0.0, 0.0)).norm() < 1e-14);
    // About z through the com: cylinder across its axis, sphere, both moved by Steiner.
    let izz = mc * (3.0 * 0.0025 + 0.16) / 12.0
        + mc * (0.2 - cx).powi(2)
        + 0.4 * ms * 0.01
        + ms * (0.5 - cx).powi(2);
    assert!(close(b.inertia[(2, 2)], izz, 1e-12));
    // About x: the cylinder's axis.
    assert!(close(
        b.inertia[(0, 0)],
        0.5 * mc * 0.0025 + 0.4 * ms * 0.01,
        1e-12
    ));
    let text = model.warnings[0].to_string();
    assert!(
        text.ends_with("from 2 <collision> primitive(s) at a density of 2000 kg/m^3 (ignored, as it cannot be weighed: capsule, mesh)"),
        "{text}"
    );
}

#[test]
fn a_mesh_only_moving_link_is_named() {
    let urdf = r#"<robot name="r"><link name="a"/>
      <link name="shell"><collision><geometry><mesh filename="s.stl"/></geometry></collision></link>
      <joint name="j" type="continuous"><parent link="a"/><child link="shell"/></joint></robot>"#;
    let o = ModelOptions {
        inertia_from_collision: Some(1000.0),
        armature: vec![("j".into(), 0.01)],
        ..ModelOptions::default()
    };
    let model = load_str(urdf, "r.urdf", &o).unwrap();
    assert_eq!(
        model.warnings,
        [ModelWarning::NoCollisionPrimitive {
            file: "r.urdf".into(),
            link: "shell".into(),
            ignored: vec!["mesh".into()],
        }]
    );
    // Without rotor inertia the massless link makes M singular: an error naming the joint.
    let o = ModelOptions {
        inertia_from_collision: Some(1000.0),
        ..ModelOptions::default()
    };
    let e = load_str(urdf, "r.urdf", &o).unwrap_err().to_string();
    assert!(e.contains("joint `j` moves nothing with inertia"), "{e}");
    // A primitive with a negative size is an error naming the link.
    let bad = urdf.replace(
        r#"<mesh filename="s.stl"/>"#,
        r#"<box size="0.1 -0.1 0.1"/>"#,
    );
    let e = load_str(&bad, "r.urdf", &o).unwrap_err();
    assert!(matches!(e, ModelError::InvalidCollision { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("link `shell` has an invalid <collision>"),
        "{e}"
    );
}

#[test]
fn generated_code_gains_friction_only_when_asked() {
    let builder = || eomgen::Builder::new(fixture()).inertia_from_collision(1000.0);
    let plain = builder().generate().unwrap();
    assert!(!plain.contains("fn friction"));
    // Zero rotor inertia and friction off change nothing at all.
    let zero = builder()
        .armature([("shoulder", 0.0)])
        .friction(false)
        .generate()
        .unwrap();
    assert_eq!(zero, plain);
    let with = builder()
        .friction(true)
        .armature(ARMATURE)
        .generate()
        .unwrap();
    assert!(with.contains("pub fn friction(&self, qd: &[T; 2]) -> [T; 2]"));
    assert!(with.contains("`tau = M qdd + b + G + F(qd)`: includes the joint friction"));
    assert!(with.contains("rotor inertia (armature): `shoulder` 0.2, `elbow` 0.05."));
    assert!(with.contains("qd[0].signum()"));
    let smooth = builder()
        .friction(true)
        .coulomb_smoothing(0.01)
        .generate()
        .unwrap();
    assert!(smooth.contains(".sqrt()") && !smooth.contains("signum"));
    // Errors surface from generation too.
    let e = builder().armature([("nope", 1.0)]).generate().unwrap_err();
    assert!(e
        .to_string()
        .contains("armature: joint `nope` does not exist"));
}

#[test]
fn symbolic_parameters_include_the_joint_effects() {
    use eomgen::SymbolicParams;
    let source = eomgen::Builder::new(fixture())
        .inertia_from_collision(1000.0)
        .symbolic(SymbolicParams::All)
        .friction(true)
        .armature([("shoulder", 0.2)])
        .generate()
        .unwrap();
    for field in [
        "/// `Ia_shoulder` (armature option value 0.2).\n    pub ia_shoulder: T,",
        "/// `damping_elbow` (URDF value 0.1).\n    pub damping_elbow: T,",
        "/// `friction_shoulder` (URDF value 0.2).\n    pub friction_shoulder: T,",
    ] {
        assert!(source.contains(field), "missing {field}");
    }
    // Zero rotor inertia stays a structural zero, not a field.
    assert!(!source.contains("ia_elbow"));
    // The symbolic derivation at the default values is the numeric one.
    let o = options(|o| {
        o.symbolic = SymbolicParams::All;
        o.friction = true;
        o.armature = vec![("shoulder".into(), 0.2)];
    });
    let symbolic = Derivation::new(&load(&o));
    let numeric = Derivation::new(&load(&ModelOptions {
        symbolic: SymbolicParams::None,
        ..o
    }));
    let s = &states(2)[3];
    let value = |d: &Derivation, ids: &[Id]| {
        Program::new(&d.graph, ids)
            .eval(|sym| match sym.kind {
                SymbolKind::Q(i) => Some(s.q[i]),
                SymbolKind::Qd(i) => Some(s.qd[i]),
                SymbolKind::Qdd(i) => Some(s.qdd[i]),
                SymbolKind::Param => d.params.iter().find(|p| p.0 == sym.name).map(|p| p.2),
                SymbolKind::Tau(_) | SymbolKind::Force(_) => None,
            })
            .unwrap()
    };
    let (a, b) = (
        value(&symbolic, &symbolic.fast.tau.1),
        value(&numeric, &numeric.fast.tau.1),
    );
    for i in 0..2 {
        assert!(close(a[i], b[i], 1e-13), "{a:?} vs {b:?}");
    }
}
