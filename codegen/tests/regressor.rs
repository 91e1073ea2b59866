//! Identification in the derivation: the regressor's two routes agree, the base parameters
//! reproduce the dynamics and are as many as the regressor's rank, and their formulas are the
//! textbook ones where the textbook has them (Khalil and Dombre's planar and SCARA arms).

#![allow(clippy::needless_range_loop)]

use std::path::PathBuf;

use eomgen::cas::{Id, Program, Style, SymbolKind};
use eomgen::dynamics::newton_euler::LocalModel;
use eomgen::dynamics::regressor::{self, standard_parameters, Inputs};
use eomgen::dynamics::Derivation;
use eomgen::kinematics::{const_v3, Params};
use eomgen::model::{Model, ModelOptions};
use eomgen::urdf::{load_file, load_str};
use nalgebra::DMatrix;

fn reference(robot: &str) -> Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/robots")
        .join(format!("{robot}.urdf"));
    load_file(path, &ModelOptions::default()).unwrap()
}

/// Deterministic states: (q, qd, qdd) with entries in [-2, 2].
fn states(n: usize, count: usize) -> Vec<[Vec<f64>; 3]> {
    let mut x = 0.37_f64;
    let mut next = move || {
        x = (x * 7.13 + 0.291).fract();
        4.0 * x - 2.0
    };
    (0..count)
        .map(|_| [0, 1, 2].map(|_| (0..n).map(|_| next()).collect()))
        .collect()
}

fn eval(d: &Derivation, outputs: &[Id], s: &[Vec<f64>; 3]) -> Vec<f64> {
    Program::new(&d.graph, outputs)
        .eval(|sym| match sym.kind {
            SymbolKind::Q(i) => Some(s[0][i]),
            SymbolKind::Qd(i) => Some(s[1][i]),
            SymbolKind::Qdd(i) => Some(s[2][i]),
            SymbolKind::Tau(_) | SymbolKind::Force(_) | SymbolKind::Param => None,
        })
        .expect("numeric model")
}

fn flat(m: &[Vec<Id>]) -> Vec<Id> {
    m.iter().flatten().copied().collect()
}

/// Derives `model` with identification.
fn identified(model: &Model) -> Derivation {
    let mut d = Derivation::new(model);
    d.add_regressor(model).unwrap();
    d
}

/// `Y pi = Y_b pi_b = tau` at many states, and `P = rank Y`; returns P.
fn check_base(model: &Model) -> usize {
    let d = identified(model);
    let id = d.identification.as_ref().unwrap();
    let n = model.dof();
    let values: Vec<Id> = id.parameters.iter().map(|p| p.value).collect();
    let base: Vec<Id> = id.base.iter().map(|b| b.value).collect();
    let pi = eval(&d, &values, &states(n, 1)[0]);
    let pib = eval(&d, &base, &states(n, 1)[0]);
    let (p, pb) = (pi.len(), pib.len());
    let count = 3 * p / n + 10;
    let mut rows = Vec::new();
    for s in states(n, count) {
        let y = eval(&d, &flat(&id.regressor), &s);
        let yb = eval(&d, &flat(&id.base_regressor), &s);
        let tau = eval(&d, &d.fast.tau.1, &s);
        for i in 0..n {
            let full: f64 = (0..p).map(|k| y[i * p + k] * pi[k]).sum();
            let reduced: f64 = (0..pb).map(|k| yb[i * pb + k] * pib[k]).sum();
            let scale = tau[i].abs().max(1.0);
            assert!(
                (full - tau[i]).abs() < 1e-10 * scale,
                "{}: Y pi",
                model.name
            );
            assert!(
                (reduced - tau[i]).abs() < 1e-10 * scale,
                "{}: Y_b pi_b",
                model.name
            );
            rows.push(y[i * p..(i + 1) * p].to_vec());
        }
    }
    let m = DMatrix::from_fn(rows.len(), p, |i, j| rows[i][j]);
    let tol = 1e-8 * m.amax().max(1.0) * rows.len() as f64;
    assert_eq!(
        m.rank(tol),
        pb,
        "{}: P is the rank of the regressor",
        model.name
    );
    pb
}

/// The formulas as `name = formula` lines, 6 significant digits.
fn formulas(d: &mut Derivation) -> Vec<String> {
    let id = d.identification.clone().unwrap();
    let style = Style {
        digits: Some(6),
        ..Style::default()
    };
    id.base
        .iter()
        .map(|b| format!("{} = {}", b.name, id.formula(&mut d.graph, b, style, 1e-12)))
        .collect()
}

#[test]
fn both_routes_to_the_regressor_agree() {
    for robot in [
        "double_pendulum",
        "ur5",
        "panda",
        "kinova",
        "allegro_right_hand",
    ] {
        let model = reference(robot);
        let mut d = Derivation::new(&model);
        let g = &mut d.graph;
        let params = Params::new(g, &model);
        let lm = LocalModel::new(g, &model, &params, &d.q);
        let parameters = standard_parameters(g, &model, &lm, &params);
        let inputs = Inputs {
            model: &model,
            lm: &lm,
            params: &params,
            parameters: &parameters,
            qd: &d.qd,
            qdd: &d.qdd,
            gravity: const_v3(g, &model.gravity),
        };
        let a = regressor::projected(g, &inputs).unwrap();
        let b = regressor::differentiated(g, &inputs).unwrap();
        for s in states(model.dof(), 4) {
            let (ya, yb) = (eval(&d, &flat(&a), &s), eval(&d, &flat(&b), &s));
            for (x, y) in ya.iter().zip(&yb) {
                assert!((x - y).abs() < 1e-12 * y.abs().max(1.0), "{robot}: {x} {y}");
            }
        }
    }
}

#[test]
fn base_parameters_are_minimal_and_exact_on_the_reference_robots() {
    let p: Vec<usize> = [
        "double_pendulum",
        "ur5",
        "panda",
        "kinova",
        "allegro_right_hand",
    ]
    .iter()
    .map(|r| check_base(&reference(r)))
    .collect();
    assert_eq!(p, [6, 36, 51, 36, 94]);
}

/// A planar arm of two links of length 0.5 m (each body's frame at its joint), with `axis`
/// for both joints, an optional prismatic third joint along `slide`, and rotor inertia on
/// the first joint.
fn planar(axis: &str, slide: Option<&str>, armature: f64) -> Model {
    let link = |name: &str, com: &str| {
        format!(
            r#"<link name="{name}"><inertial><origin xyz="{com}"/><mass value="2"/>
            <inertia ixx="0.03" ixy="0.001" ixz="0.002" iyy="0.04" iyz="0.003" izz="0.05"/></inertial></link>"#
        )
    };
    let joint = |name: &str, kind: &str, parent: &str, child: &str, xyz: &str, axis: &str| {
        format!(
            r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
            <origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>"#
        )
    };
    let mut urdf = String::from(r#"<robot name="planar"><link name="base"/>"#);
    urdf += &link("l1", "0.2 0.01 0.02");
    urdf += &link("l2", "0.25 -0.01 0.03");
    urdf += &joint("j1", "revolute", "base", "l1", "0 0 0", axis);
    urdf += &joint("j2", "revolute", "l1", "l2", "0.5 0 0", axis);
    if let Some(s) = slide {
        urdf += &link("l3", "0.01 0.02 0.05");
        urdf += &joint("j3", "prismatic", "l2", "l3", "0.5 0 0", s);
    }
    urdf += "</robot>";
    let options = ModelOptions {
        armature: vec![("j1".into(), armature)],
        ..ModelOptions::default()
    };
    load_str(&urdf, "planar.urdf", &options).unwrap()
}

/// Khalil and Dombre's SCARA-like planar arm, axes parallel to gravity: four base parameters,
/// `ZZR1 = ZZ1 + a2^2 M2` with ZZ2, MX2 and MY2 apart, and gravity plays no part.
#[test]
fn a_horizontal_planar_arm_has_the_textbook_base_parameters() {
    let model = planar("0 0 1", None, 0.0);
    assert_eq!(check_base(&model), 4);
    let mut d = identified(&model);
    assert_eq!(
        formulas(&mut d),
        [
            "ZZR_l1 = ZZ_l1 + 0.25*M_l2",
            "MX_l2 = MX_l2",
            "MY_l2 = MY_l2",
            "ZZ_l2 = ZZ_l2",
        ]
    );
}

/// With gravity in the plane of motion the first link's first moments show too: six.
#[test]
fn a_vertical_planar_arm_adds_the_first_moments_of_its_first_link() {
    let model = planar("0 1 0", None, 0.0);
    assert_eq!(check_base(&model), 6);
    let mut d = identified(&model);
    let f = formulas(&mut d);
    assert!(
        f.contains(&"MXR_l1 = MX_l1 + 0.5*M_l2".to_string()),
        "{f:?}"
    );
    assert!(
        f.contains(&"YYR_l1 = YY_l1 + 0.25*M_l2".to_string()),
        "{f:?}"
    );
}

/// A prismatic joint carries its body's rotational inertia to its parent, and rotor inertia
/// on a first joint folds into that joint's inertia with coefficient 1.
#[test]
fn prismatic_joints_and_rotor_inertia_group_exactly() {
    for slide in ["1 0 0", "0 0 1", "0.6 0 0.8"] {
        let model = planar("0 0 1", Some(slide), 0.0);
        check_base(&model);
    }
    let model = planar("0 0 1", Some("0 0 1"), 0.1);
    let p = check_base(&model);
    let mut d = identified(&model);
    let f = formulas(&mut d);
    assert_eq!(f.len(), p);
    assert!(f[0].starts_with("ZZR_l1 = ZZ_l1 + "), "{f:?}");
    assert!(
        f[0].contains(" + IA_j1"),
        "rotor inertia folds into ZZR_l1: {f:?}"
    );
    assert!(!f.iter().any(|l| l.starts_with("IA")), "{f:?}");
}
