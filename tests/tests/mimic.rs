//! Mimic joints honoured (`Builder::mimic_joints`), through compiled generated code:
//!
//! - the panda, whose second finger follows the first, against Pinocchio with the mimic tag
//!   honoured (`robots/panda.mimic.json`), 1e-9 relative;
//! - `fixtures/mimic_tree.urdf`, a tree we do not ship with every kind of coupling (a negative
//!   multiplier and offsets, a chain of mimics, a prismatic mimic, a mimic across branches,
//!   friction and rotor inertia on mimic joints), against the same tree generated without
//!   the option: with the coupling written out here from the URDF, `q_joints = G q + o`, every
//!   quantity must be the full tree's projected (`M = G^T M_full G`, `tau = G^T tau_full`,
//!   `J = J_full G`, ...);
//! - physics identities and the derivatives against finite differences on both.

#![allow(clippy::needless_range_loop)]

use eomgen_runtime::{Contacts, Dynamics, FloatingDynamics, Pose};
use eomgen_tests::robots::{
    mimic_tree, mimic_tree_floating, mimic_tree_floating_full, mimic_tree_full, panda_mimic,
};
use eomgen_tests::{Checker, JointMap};
use serde_json::Value;

type Tree = mimic_tree::MimicTree<f64>;
type Full = mimic_tree_full::MimicTreeFull<f64>;
type Panda = panda_mimic::PandaMimic<f64>;

/// A link's [`Motion`] at `(q, v, a)`.
macro_rules! motion {
    ($robot:expr, $link:expr, $q:expr, $v:expr, $a:expr) => {
        (
            $robot.link_velocity($link, $q, $v),
            $robot.link_acceleration($link, $q, $v, $a),
            $robot.link_jacobian_time_variation($link, $q, $v),
        )
    };
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn matrix(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("array").iter().map(floats).collect()
}

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    core::array::from_fn(|i| v[i])
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[test]
fn panda_with_its_mimic_finger_matches_pinocchio() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/panda.mimic.json");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let names: Vec<String> = v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap().to_string())
        .collect();
    let ours = <Panda as Dynamics<f64, 8>>::JOINT_NAMES;
    assert!(!ours.contains(&"panda_finger_joint2"), "{ours:?}");
    let map = JointMap::new(&names, &ours);
    let o = &map.ours;
    let robot = Panda::default();
    let mut c = Checker::new(1e-9);
    let mut worst_fd = 0.0_f64;
    let samples = v["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 8);
    for (s, sm) in samples.iter().enumerate() {
        let state = |key: &str| -> [f64; 8] { arr(&map.to_ours(&floats(&sm[key]))) };
        let (q, qd, qdd, tau_in) = (state("q"), state("qd"), state("qdd"), state("tau_in"));
        let m = robot.mass_matrix(&q);
        let g = robot.gravity(&q);
        let b = robot.bias(&q, &qd);
        let tau = robot.inverse_dynamics(&q, &qd, &qdd);
        let want_m = matrix(&sm["mass_matrix"]);
        let (want_g, want_b, want_tau) = (
            floats(&sm["gravity"]),
            floats(&sm["bias"]),
            floats(&sm["tau"]),
        );
        for i in 0..8 {
            for j in 0..8 {
                c.check(|| format!("#{s} M[{i}][{j}]"), m[o[i]][o[j]], want_m[i][j]);
            }
            c.check(|| format!("#{s} g[{i}]"), g[o[i]], want_g[i]);
            c.check(|| format!("#{s} b[{i}]"), b[o[i]], want_b[i]);
            c.check(|| format!("#{s} tau[{i}]"), tau[o[i]], want_tau[i]);
        }
        c.check(
            || format!("#{s} T"),
            robot.kinetic_energy(&q, &qd),
            sm["kinetic_energy"].as_f64().unwrap(),
        );
        // Forward dynamics normwise: M's conditioning (the fingers' 0.015 kg) amplifies the
        // reference's own rounding.
        let fd = robot.forward_dynamics(&q, &qd, &tau_in);
        let want = floats(&sm["forward_dynamics"]);
        let diff: Vec<f64> = (0..8).map(|i| fd[o[i]] - want[i]).collect();
        let rel = norm(&diff) / norm(&want).max(1.0);
        worst_fd = worst_fd.max(rel);
    }
    assert!(worst_fd < 1e-9, "forward dynamics: {worst_fd:e} normwise");
    c.finish("panda with mimic joints against Pinocchio");
}

/// The tree's coupling, written out from `fixtures/mimic_tree.urdf`: per joint of the full
/// tree, (coordinate name, multiplier, offset). `a3` mimics `a2` (1.5, -0.1), which mimics
/// `a1` (-0.7, 0.3): `a3 = -1.05 a1 + 0.35`.
const COUPLING: [(&str, &str, f64, f64); 8] = [
    ("j1", "j1", 1.0, 0.0),
    ("a1", "a1", 1.0, 0.0),
    ("a2", "a1", -0.7, 0.3),
    ("a3", "a1", -1.05, 0.35),
    ("b1", "b1", 1.0, 0.0),
    ("b2", "b1", 2.0, 0.01),
    ("c1", "a1", 0.5, 0.0),
    ("c2", "c2", 1.0, 0.0),
];

/// `G` (8 x 4, full joints by our coordinates, in the generated types' orders) and `o`.
fn coupling() -> (Vec<Vec<f64>>, Vec<f64>) {
    let full = <Full as Dynamics<f64, 8>>::JOINT_NAMES;
    let ours = <Tree as Dynamics<f64, 4>>::JOINT_NAMES;
    assert_eq!(ours.len(), 4);
    let mut g = vec![vec![0.0; 4]; 8];
    let mut o = vec![0.0; 8];
    for (joint, coordinate, k, offset) in COUPLING {
        let i = full.iter().position(|&n| n == joint).unwrap();
        let c = ours.iter().position(|&n| n == coordinate).unwrap();
        g[i][c] = k;
        o[i] = offset;
    }
    (g, o)
}

/// `G x` (`G` is F x N: the full tree's coordinates by ours).
fn g_times<const F: usize, const N: usize>(g: &[Vec<f64>], x: &[f64; N]) -> [f64; F] {
    core::array::from_fn(|i| (0..N).map(|c| g[i][c] * x[c]).sum())
}

/// `G^T x`.
fn g_t_times<const N: usize>(g: &[Vec<f64>], x: &[f64]) -> [f64; N] {
    core::array::from_fn(|c| (0..g.len()).map(|i| g[i][c] * x[i]).sum())
}

/// `G^T A G`.
fn project<const F: usize, const N: usize>(g: &[Vec<f64>], a: &[[f64; F]; F]) -> [[f64; N]; N] {
    let ag: [[f64; N]; F] = columns(g, a);
    core::array::from_fn(|c| core::array::from_fn(|d| (0..F).map(|i| g[i][c] * ag[i][d]).sum()))
}

/// `A G` for an R x F `A`.
fn columns<const R: usize, const F: usize, const N: usize>(
    g: &[Vec<f64>],
    a: &[[f64; F]; R],
) -> [[f64; N]; R] {
    core::array::from_fn(|r| g_t_times(g, &a[r]))
}

/// Checks matrices and vectors by name against their expected values.
#[allow(clippy::type_complexity)]
fn same<const N: usize>(
    c: &mut Checker,
    s: usize,
    matrices: &[(&str, &[[f64; N]; N], &[[f64; N]; N])],
    vectors: &[(&str, [f64; N], [f64; N])],
) {
    for i in 0..N {
        for (name, got, want) in matrices {
            for j in 0..N {
                c.check(|| format!("#{s} {name}[{i}][{j}]"), got[i][j], want[i][j]);
            }
        }
        for (name, got, want) in vectors {
            c.check(|| format!("#{s} {name}[{i}]"), got[i], want[i]);
        }
    }
}

/// Checks a link's pose and Jacobian against the full tree's (Jacobian already projected).
fn same_link<const N: usize>(
    c: &mut Checker,
    what: &str,
    (pose, want_pose): (&Pose<f64>, &Pose<f64>),
    jacobian: &[[f64; N]; 6],
    want_jacobian: &[[f64; N]; 6],
) {
    for r in 0..3 {
        let (got, want) = (pose.translation[r], want_pose.translation[r]);
        c.check(|| format!("{what} position[{r}]"), got, want);
        for k in 0..3 {
            let (got, want) = (pose.rotation[r][k], want_pose.rotation[r][k]);
            c.check(|| format!("{what} rotation[{r}][{k}]"), got, want);
        }
    }
    for r in 0..6 {
        for k in 0..N {
            let (got, want) = (jacobian[r][k], want_jacobian[r][k]);
            c.check(|| format!("{what} J[{r}][{k}]"), got, want);
        }
    }
}

/// Deterministic states with entries in [-1.5, 1.5].
fn states<const N: usize>(count: usize) -> Vec<[[f64; N]; 4]> {
    let mut x = 0.4142_f64;
    let mut next = move || {
        x = (x * 9.73 + 0.377).fract();
        3.0 * x - 1.5
    };
    (0..count)
        .map(|_| core::array::from_fn(|_| core::array::from_fn(|_| next())))
        .collect()
}

#[test]
fn the_tree_with_mimic_joints_is_the_full_tree_projected() {
    let (gm, off) = coupling();
    let (tree, full) = (Tree::default(), Full::default());
    let mut c = Checker::new(1e-10);
    for (s, [q, qd, qdd, tau_in]) in states::<4>(8).into_iter().enumerate() {
        let mut qf = g_times(&gm, &q);
        for i in 0..8 {
            qf[i] += off[i];
        }
        let (qdf, qddf) = (g_times(&gm, &qd), g_times(&gm, &qdd));
        let m = tree.mass_matrix(&q);
        let want_m = project(&gm, &full.mass_matrix(&qf));
        let cm = tree.coriolis_matrix(&q, &qd);
        let want_cm = project(&gm, &full.coriolis_matrix(&qf, &qdf));
        let vectors = [
            (
                "tau",
                tree.inverse_dynamics(&q, &qd, &qdd),
                g_t_times(&gm, &full.inverse_dynamics(&qf, &qdf, &qddf)),
            ),
            ("g", tree.gravity(&q), g_t_times(&gm, &full.gravity(&qf))),
            (
                "b",
                tree.bias(&q, &qd),
                g_t_times(&gm, &full.bias(&qf, &qdf)),
            ),
            (
                "F",
                tree.friction(&qd),
                g_t_times(&gm, &full.friction(&qdf)),
            ),
        ];
        same(
            &mut c,
            s,
            &[("M", &m, &want_m), ("C", &cm, &want_cm)],
            &vectors,
        );
        let scalars = [
            (
                "T",
                tree.kinetic_energy(&q, &qd),
                full.kinetic_energy(&qf, &qdf),
            ),
            ("V", tree.potential_energy(&q), full.potential_energy(&qf)),
        ];
        for (name, got, want) in scalars {
            c.check(|| format!("#{s} {name}"), got, want);
        }
        // The regressor: G^T Y_full over the same standard parameters, which reproduce tau,
        // as the base parameters do with the base regressor.
        let (y, want_y) = (
            tree.regressor(&q, &qd, &qdd),
            full.regressor(&qf, &qdf, &qddf),
        );
        let (pi, pi_b, y_b) = (
            tree.parameters(),
            tree.base_parameters(),
            tree.base_regressor(&q, &qd, &qdd),
        );
        let tau = tree.inverse_dynamics(&q, &qd, &qdd);
        assert_eq!(pi, full.parameters());
        for i in 0..4 {
            for p in 0..pi.len() {
                let want: f64 = (0..8).map(|j| gm[j][i] * want_y[j][p]).sum();
                c.check(|| format!("#{s} Y[{i}][{p}]"), y[i][p], want);
            }
            let y_pi: f64 = (0..pi.len()).map(|p| y[i][p] * pi[p]).sum();
            let yb_pib: f64 = (0..pi_b.len()).map(|p| y_b[i][p] * pi_b[p]).sum();
            c.check(|| format!("#{s} (Y pi)[{i}]"), y_pi, tau[i]);
            c.check(|| format!("#{s} (Y_b pi_b)[{i}]"), yb_pib, tau[i]);
        }
        // Forward dynamics: the full tree's equations of motion, projected, hold.
        let fd = tree.forward_dynamics(&q, &qd, &tau_in);
        let tau_back: [f64; 4] =
            g_t_times(&gm, &full.inverse_dynamics(&qf, &qdf, &g_times(&gm, &fd)));
        for i in 0..4 {
            c.check(|| format!("#{s} ID(FD)[{i}]"), tau_back[i], tau_in[i]);
        }
        // Link kinematics: every URDF link, by name in both link enums.
        for (link, full_link) in mimic_tree::MimicTreeLink::ALL
            .iter()
            .zip(mimic_tree_full::MimicTreeFullLink::ALL)
        {
            assert_eq!(link.name(), full_link.name());
            same_link(
                &mut c,
                &format!("#{s} {}", link.name()),
                (&tree.link_pose(*link, &q), &full.link_pose(full_link, &qf)),
                &tree.link_jacobian(*link, &q),
                &columns(&gm, &full.link_jacobian(full_link, &qf)),
            );
            let ours = motion!(tree, *link, &q, &qd, &qdd);
            let want = motion!(full, full_link, &qf, &qdf, &qddf);
            same_motion(&mut c, &format!("#{s} {}", link.name()), ours, want, &gm);
        }
        let (com, want_com) = (tree.center_of_mass(&q), full.center_of_mass(&qf));
        let jc = tree.center_of_mass_jacobian(&q);
        let want_jc: [[f64; 4]; 3] = columns(&gm, &full.center_of_mass_jacobian(&qf));
        for r in 0..3 {
            c.check(|| format!("#{s} com[{r}]"), com[r], want_com[r]);
            for k in 0..4 {
                c.check(|| format!("#{s} com J[{r}][{k}]"), jc[r][k], want_jc[r][k]);
            }
        }
        // Craig's matrices: the Christoffel symbols of the reduced M, whose contractions the
        // (projected) C(q, qd) is: C(q)_ij = C(q, e_j)_ij, B_i,(jk) = 2 C(q, e_k)_ij.
        let (cf, cp) = (tree.centrifugal(&q), tree.coriolis_pairs(&q));
        let unit = |k: usize| -> [f64; 4] { core::array::from_fn(|i| f64::from(u8::from(i == k))) };
        let mut pair = 0;
        for j in 0..4 {
            let cj = tree.coriolis_matrix(&q, &unit(j));
            for i in 0..4 {
                c.check(|| format!("#{s} Craig C[{i}][{j}]"), cf[i][j], cj[i][j]);
            }
            for k in j + 1..4 {
                let ck = tree.coriolis_matrix(&q, &unit(k));
                for i in 0..4 {
                    c.check(
                        || format!("#{s} Craig B[{i}][({j},{k})]"),
                        cp[i][pair],
                        2.0 * ck[i][j],
                    );
                }
                pair += 1;
            }
        }
    }
    c.finish("mimic tree against the full tree projected");
}

/// `M` symmetric positive definite, `C qd = b`, `dM/dt - 2 C` skew-symmetric (dM/dt by
/// central differences along qd), `g = dV/dq` (central differences), `T = qd M qd / 2`, and
/// forward dynamics solving `M qdd = tau - b - g - F`.
fn identities<R: Dynamics<f64, N>, const N: usize>(
    robot: &R,
    friction: impl Fn(&[f64; N]) -> [f64; N],
    what: &str,
) {
    let mut c = Checker::new(1e-6);
    let h = 1e-6;
    for (s, [q, qd, _, tau_in]) in states::<N>(6).into_iter().enumerate() {
        let m = robot.mass_matrix(&q);
        // Cholesky: every pivot positive.
        let mut l = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..=i {
                let sum: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
                if i == j {
                    let d = m[i][i] - sum;
                    assert!(d > 0.0, "{what} #{s}: M not positive definite (pivot {i})");
                    l[i][i] = d.sqrt();
                } else {
                    l[i][j] = (m[i][j] - sum) / l[j][j];
                }
            }
        }
        let cm = robot.coriolis_matrix(&q, &qd);
        let b = robot.bias(&q, &qd);
        let step = |k: f64| -> [f64; N] { core::array::from_fn(|i| q[i] + k * h * qd[i]) };
        let (mp, mm) = (
            robot.mass_matrix(&step(1.0)),
            robot.mass_matrix(&step(-1.0)),
        );
        let g = robot.gravity(&q);
        for i in 0..N {
            let cqd: f64 = (0..N).map(|j| cm[i][j] * qd[j]).sum();
            c.check(|| format!("{what} #{s} (C qd)[{i}]"), cqd, b[i]);
            for j in 0..N {
                c.check(|| format!("{what} #{s} M sym[{i}][{j}]"), m[i][j], m[j][i]);
                let n = |i: usize, j: usize| (mp[i][j] - mm[i][j]) / (2.0 * h) - 2.0 * cm[i][j];
                c.check(|| format!("{what} #{s} skew[{i}][{j}]"), n(i, j), -n(j, i));
            }
            let mut qp = q;
            let mut qm = q;
            qp[i] += h;
            qm[i] -= h;
            let dv = (robot.potential_energy(&qp) - robot.potential_energy(&qm)) / (2.0 * h);
            c.check(|| format!("{what} #{s} dV/dq[{i}]"), dv, g[i]);
        }
        let t: f64 = (0..N)
            .map(|i| (0..N).map(|j| qd[i] * m[i][j] * qd[j]).sum::<f64>())
            .sum::<f64>()
            / 2.0;
        c.check(
            || format!("{what} #{s} T"),
            robot.kinetic_energy(&q, &qd),
            t,
        );
        let fd = robot.forward_dynamics(&q, &qd, &tau_in);
        let f = friction(&qd);
        for i in 0..N {
            let mqdd: f64 = (0..N).map(|j| m[i][j] * fd[j]).sum();
            c.check(
                || format!("{what} #{s} M fd[{i}]"),
                mqdd + b[i] + g[i] + f[i],
                tau_in[i],
            );
        }
    }
    c.finish(what);
}

#[test]
fn physics_identities_hold_with_mimic_joints() {
    let tree = Tree::default();
    identities(&tree, |qd| tree.friction(qd), "mimic tree");
    identities(&Panda::default(), |_| [0.0; 8], "panda with mimic");
}

/// The derivatives against central differences of the compiled inverse and forward dynamics,
/// and `M^-1` (the run-time tree solve over the coordinates' parents) against `M`.
fn derivatives<const N: usize>(
    id: impl Fn(&[f64; N], &[f64; N], &[f64; N]) -> [f64; N],
    fd: impl Fn(&[f64; N], &[f64; N], &[f64; N]) -> [f64; N],
    id_d: impl Fn(&[f64; N], &[f64; N], &[f64; N]) -> ([[f64; N]; N], [[f64; N]; N]),
    fd_d: impl Fn(&[f64; N], &[f64; N], &[f64; N]) -> ([[f64; N]; N], [[f64; N]; N], [[f64; N]; N]),
    m: impl Fn(&[f64; N]) -> [[f64; N]; N],
    what: &str,
) {
    let mut c = Checker::new(1e-5);
    let h = 1e-6;
    for (s, [q, qd, qdd, tau]) in states::<N>(4).into_iter().enumerate() {
        let (dq, dqd) = id_d(&q, &qd, &qdd);
        let (fq, fqd, minv) = fd_d(&q, &qd, &tau);
        for j in 0..N {
            let shifted = |x: &[f64; N], k: f64| -> [f64; N] {
                let mut y = *x;
                y[j] += k * h;
                y
            };
            let num = |a: [f64; N], b: [f64; N]| -> Vec<f64> {
                (0..N).map(|i| (a[i] - b[i]) / (2.0 * h)).collect()
            };
            let cols = [
                (
                    "dtau/dq",
                    num(
                        id(&shifted(&q, 1.0), &qd, &qdd),
                        id(&shifted(&q, -1.0), &qd, &qdd),
                    ),
                    &dq,
                ),
                (
                    "dtau/dqd",
                    num(
                        id(&q, &shifted(&qd, 1.0), &qdd),
                        id(&q, &shifted(&qd, -1.0), &qdd),
                    ),
                    &dqd,
                ),
                (
                    "dfd/dq",
                    num(
                        fd(&shifted(&q, 1.0), &qd, &tau),
                        fd(&shifted(&q, -1.0), &qd, &tau),
                    ),
                    &fq,
                ),
                (
                    "dfd/dqd",
                    num(
                        fd(&q, &shifted(&qd, 1.0), &tau),
                        fd(&q, &shifted(&qd, -1.0), &tau),
                    ),
                    &fqd,
                ),
            ];
            for (name, want, got) in &cols {
                for i in 0..N {
                    c.check(
                        || format!("{what} #{s} {name}[{i}][{j}]"),
                        got[i][j],
                        want[i],
                    );
                }
            }
        }
        let mm = m(&q);
        for i in 0..N {
            for j in 0..N {
                let p: f64 = (0..N).map(|k| minv[i][k] * mm[k][j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                c.check(|| format!("{what} #{s} (M^-1 M)[{i}][{j}]"), p, want);
            }
        }
    }
    c.finish(what);
}

#[test]
fn derivatives_with_mimic_joints_match_finite_differences() {
    let tree = Tree::default();
    derivatives(
        |q, qd, qdd| tree.inverse_dynamics(q, qd, qdd),
        |q, qd, tau| tree.forward_dynamics(q, qd, tau),
        |q, qd, qdd| tree.inverse_dynamics_derivatives(q, qd, qdd),
        |q, qd, tau| tree.forward_dynamics_derivatives(q, qd, tau),
        |q| tree.mass_matrix(q),
        "mimic tree",
    );
    let panda = Panda::default();
    derivatives(
        |q, qd, qdd| panda.inverse_dynamics(q, qd, qdd),
        |q, qd, tau| panda.forward_dynamics(q, qd, tau),
        |q, qd, qdd| panda.inverse_dynamics_derivatives(q, qd, qdd),
        |q, qd, tau| panda.forward_dynamics_derivatives(q, qd, tau),
        |q| panda.mass_matrix(q),
        "panda with mimic",
    );
}

/// The run-time `L^T D L` solves (used by larger robots' forward dynamics, `M^-1` and contact
/// dynamics) over the coordinates' parents: `c1` follows `a1` across branches, so `c2`, below
/// `c1`, becomes a child of `a1`'s coordinate, while `b1` stays a branch of its own.
#[test]
fn the_run_time_tree_solve_handles_a_mimic_across_branches() {
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/mimic_tree.urdf");
    let builder = eomgen::Builder::new(urdf).mimic_joints();
    let model = builder.model().unwrap();
    let d = builder.derive(&model).unwrap();
    let parents: [Option<usize>; 4] = d.coordinate_parents.clone().try_into().unwrap();
    assert_eq!(
        <Tree as Dynamics<f64, 4>>::JOINT_NAMES,
        ["j1", "a1", "b1", "c2"]
    );
    assert_eq!(parents, [None, Some(0), Some(0), Some(1)]);
    let tree = Tree::default();
    let mut c = Checker::new(1e-10);
    for (s, [q, _, _, rhs]) in states::<4>(6).into_iter().enumerate() {
        let m = tree.mass_matrix(&q);
        let x = eomgen_runtime::tree::ltdl_solve(&mut m.clone(), &parents, &rhs).unwrap();
        let inv = eomgen_runtime::tree::ltdl_inverse(&mut m.clone(), &parents).unwrap();
        for i in 0..4 {
            let mx: f64 = (0..4).map(|j| m[i][j] * x[j]).sum();
            c.check(|| format!("#{s} (M x)[{i}]"), mx, rhs[i]);
            for j in 0..4 {
                let p: f64 = (0..4).map(|k| m[i][k] * inv[k][j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                c.check(|| format!("#{s} (M M^-1)[{i}][{j}]"), p, want);
            }
        }
    }
    c.finish("run-time solve with a cross-branch mimic");
}

/// The floating tree's `G`: the base's six velocity coordinates unchanged, then the joints'.
fn floating_coupling() -> (Vec<Vec<f64>>, Vec<f64>) {
    let (gm, off) = coupling();
    let mut g = vec![vec![0.0; 10]; 14];
    let mut o = vec![0.0; 14];
    for i in 0..6 {
        g[i][i] = 1.0;
    }
    for i in 0..8 {
        for c in 0..4 {
            g[6 + i][6 + c] = gm[i][c];
        }
        o[6 + i] = off[i];
    }
    (g, o)
}

#[test]
fn the_floating_tree_with_mimic_joints_is_the_full_floating_tree_projected() {
    use mimic_tree_floating::{MimicTreeFloating, MimicTreeFloatingLink};
    use mimic_tree_floating_full::{MimicTreeFloatingFull, MimicTreeFloatingFullLink};
    let (gm, off) = floating_coupling();
    let (tree, full) = (
        MimicTreeFloating::<f64>::default(),
        MimicTreeFloatingFull::<f64>::default(),
    );
    assert_eq!(
        MimicTreeFloating::<f64>::JOINT_NAMES,
        ["j1", "a1", "b1", "c2"]
    );
    let gv = |x: &[f64; 10]| -> [f64; 14] { g_times(&gm, x) };
    let gt = |x: &[f64]| -> [f64; 10] { g_t_times(&gm, x) };
    let proj = |a: &[[f64; 14]; 14]| -> [[f64; 10]; 10] { project(&gm, a) };
    let mut c = Checker::new(1e-10);
    for (s, [x, v, a, tau]) in states::<10>(6).into_iter().enumerate() {
        // q = [position, unit quaternion, the 4 coordinates].
        let n = norm(&x[3..7]);
        let mut q = [0.0; 11];
        q[..3].copy_from_slice(&x[..3]);
        for k in 0..4 {
            q[3 + k] = x[3 + k] / n;
            q[7 + k] = x[6 + k];
        }
        let mut qf = [0.0; 15];
        qf[..7].copy_from_slice(&q[..7]);
        let joints: [f64; 10] = core::array::from_fn(|i| if i < 6 { 0.0 } else { q[1 + i] });
        let jf = gv(&joints);
        for i in 0..8 {
            qf[7 + i] = jf[6 + i] + off[6 + i];
        }
        let (vf, af) = (gv(&v), gv(&a));
        let m = tree.mass_matrix(&q);
        let want_m = proj(&full.mass_matrix(&qf));
        let cm = tree.coriolis_matrix(&q, &v);
        let want_cm = proj(&full.coriolis_matrix(&qf, &vf));
        let vectors = [
            (
                "tau",
                tree.inverse_dynamics(&q, &v, &a),
                gt(&full.inverse_dynamics(&qf, &vf, &af)),
            ),
            ("g", tree.gravity(&q), gt(&full.gravity(&qf))),
            ("b", tree.bias(&q, &v), gt(&full.bias(&qf, &vf))),
        ];
        same(
            &mut c,
            s,
            &[("M", &m, &want_m), ("C", &cm, &want_cm)],
            &vectors,
        );
        c.check(
            || format!("#{s} T"),
            tree.kinetic_energy(&q, &v),
            full.kinetic_energy(&qf, &vf),
        );
        c.check(
            || format!("#{s} V"),
            tree.potential_energy(&q),
            full.potential_energy(&qf),
        );
        let fd = tree.forward_dynamics(&q, &v, &tau);
        let back = gt(&full.inverse_dynamics(&qf, &vf, &gv(&fd)));
        for i in 0..10 {
            c.check(|| format!("#{s} ID(FD)[{i}]"), back[i], tau[i]);
        }
        let rows = |a: &[[f64; 14]]| -> Vec<[f64; 10]> { a.iter().map(|r| gt(r)).collect() };
        let (com, want_com) = (tree.center_of_mass(&q), full.center_of_mass(&qf));
        let jc = tree.center_of_mass_jacobian(&q);
        let want_jc = rows(&full.center_of_mass_jacobian(&qf));
        let ag = tree.centroidal_map(&q);
        let want_ag = rows(&full.centroidal_map(&qf));
        let jk = tree.contact_jacobian(&q);
        let want_jk = rows(&full.contact_jacobian(&qf));
        let (drift, want_drift) = (tree.contact_drift(&q, &v), full.contact_drift(&qf, &vf));
        for r in 0..3 {
            c.check(|| format!("#{s} com[{r}]"), com[r], want_com[r]);
        }
        for (name, got, want) in [
            ("com J", &jc[..], &want_jc),
            ("A_g", &ag[..], &want_ag),
            ("contact J", &jk[..], &want_jk),
        ] {
            for r in 0..got.len() {
                for k in 0..10 {
                    c.check(|| format!("#{s} {name}[{r}][{k}]"), got[r][k], want[r][k]);
                }
            }
        }
        for r in 0..6 {
            c.check(|| format!("#{s} drift[{r}]"), drift[r], want_drift[r]);
        }
        // Contact forward dynamics: M a + b + g = tau + J^T F and J a + drift = 0.
        let (acc, forces) = tree.contact_forward_dynamics(&q, &v, &tau);
        let h = tree.bias(&q, &v);
        let g = tree.gravity(&q);
        for i in 0..10 {
            let lhs: f64 = (0..10).map(|j| m[i][j] * acc[j]).sum::<f64>() + h[i] + g[i];
            let rhs: f64 = tau[i] + (0..6).map(|r| jk[r][i] * forces[r]).sum::<f64>();
            c.check(|| format!("#{s} contact dynamics[{i}]"), lhs, rhs);
        }
        for r in 0..6 {
            let ja: f64 = (0..10).map(|k| jk[r][k] * acc[k]).sum();
            c.check(|| format!("#{s} contact held[{r}]"), ja + drift[r], 0.0);
        }
        for (link, full_link) in MimicTreeFloatingLink::ALL
            .iter()
            .zip(MimicTreeFloatingFullLink::ALL)
        {
            same_link(
                &mut c,
                &format!("#{s} {}", link.name()),
                (&tree.link_pose(*link, &q), &full.link_pose(full_link, &qf)),
                &tree.link_jacobian(*link, &q),
                &columns(&gm, &full.link_jacobian(full_link, &qf)),
            );
            let ours = motion!(tree, *link, &q, &v, &a);
            let want = motion!(full, full_link, &qf, &vf, &af);
            same_motion(&mut c, &format!("#{s} {}", link.name()), ours, want, &gm);
        }
        let rate = tree.centroidal_momentum_rate(&q, &v, &a);
        let want_rate = full.centroidal_momentum_rate(&qf, &vf, &af);
        for r in 0..6 {
            c.check(
                || format!("#{s} centroidal momentum rate[{r}]"),
                rate[r],
                want_rate[r],
            );
        }
        // Integration moves the coordinates by v dt (the base on SE(3), as the full tree's).
        let (qn, want_qn) = (tree.integrate(&q, &v, 0.01), full.integrate(&qf, &vf, 0.01));
        for k in 0..7 {
            c.check(|| format!("#{s} integrate[{k}]"), qn[k], want_qn[k]);
        }
    }
    c.finish("floating mimic tree against the full floating tree projected");
}

/// A link's velocity, classical acceleration and Jacobian time variation.
type Motion<const N: usize> = ([f64; 6], [f64; 6], [[f64; N]; 6]);

/// Checks a link's motion against the full tree's at the joints' rates `G v`, `G a`
/// (Jacobian time variation projected, `dJ G`).
fn same_motion<const N: usize, const F: usize>(
    c: &mut Checker,
    what: &str,
    (vel, acc, dj): Motion<N>,
    (want_vel, want_acc, want_dj): Motion<F>,
    g: &[Vec<f64>],
) {
    let want_dj: [[f64; N]; 6] = columns(g, &want_dj);
    for r in 0..6 {
        c.check(|| format!("{what} velocity[{r}]"), vel[r], want_vel[r]);
        c.check(|| format!("{what} acceleration[{r}]"), acc[r], want_acc[r]);
        for k in 0..N {
            c.check(|| format!("{what} dJ[{r}][{k}]"), dj[r][k], want_dj[r][k]);
        }
    }
}
