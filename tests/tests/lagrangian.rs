//! The Lagrangian engine, evaluated by the CAS interpreter, against Pinocchio's reference values
//! on all five robots, and against physics identities at random states.

#![allow(clippy::needless_range_loop)]

use eomgen::cas::{Id, Program, SymbolKind};
use eomgen::dynamics::Derivation;
use eomgen::model::ModelOptions;
use eomgen_tests::{load, urdf_path, Checker, JointMap, ROBOTS};

fn derive(robot: &str) -> (eomgen::model::Model, Derivation) {
    let model = eomgen::urdf::load_file(urdf_path(robot), &ModelOptions::default()).expect("loads");
    let d = Derivation::new(&model);
    (model, d)
}

/// Evaluates `outputs` at a state given in our joint order.
fn run(p: &Program, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    p.eval(|s| match s.kind {
        SymbolKind::Q(i) => Some(q[i]),
        SymbolKind::Qd(i) => Some(qd[i]),
        SymbolKind::Qdd(i) => Some(qdd[i]),
        SymbolKind::Tau(_) | SymbolKind::Force(_) | SymbolKind::Param => None,
    })
    .expect("numeric model")
}

/// Evaluates `outputs` with the joint efforts `tau` too (inputs of forward dynamics).
fn run_with_tau(p: &Program, q: &[f64], qd: &[f64], qdd: &[f64], tau: &[f64]) -> Vec<f64> {
    p.eval(|s| match s.kind {
        SymbolKind::Q(i) => Some(q[i]),
        SymbolKind::Qd(i) => Some(qd[i]),
        SymbolKind::Qdd(i) => Some(qdd[i]),
        SymbolKind::Tau(i) => Some(tau[i]),
        SymbolKind::Force(_) | SymbolKind::Param => None,
    })
    .expect("numeric model")
}

/// Lays out every quantity in one output list, remembering where each starts.
struct Layout {
    outputs: Vec<Id>,
}

impl Layout {
    fn push(&mut self, ids: impl IntoIterator<Item = Id>) -> usize {
        let at = self.outputs.len();
        self.outputs.extend(ids);
        at
    }
}

#[test]
fn every_quantity_matches_pinocchio_on_every_robot() {
    for robot in ROBOTS {
        let reference = load(robot);
        let (model, mut d) = derive(robot);
        let frames = d.frames(&model);
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let map = JointMap::new(&reference.joints, &names);
        let n = d.dof;
        let mut l = Layout {
            outputs: Vec::new(),
        };
        let m_at = l.push(d.mass_matrix.iter().flatten().copied());
        let g_at = l.push(d.gravity.iter().copied());
        let b_at = l.push(d.bias.iter().copied());
        let c_at = l.push(d.coriolis_matrix.iter().flatten().copied());
        let t_at = l.push(d.tau.iter().copied());
        let ke_at = l.push([d.kinetic_energy]);
        let pe_at = l.push([d.potential_energy]);
        let cf_at = l.push(d.centrifugal.iter().flatten().copied());
        let np = n * (n - 1) / 2;
        let cp_at = l.push(d.coriolis_pairs.iter().flatten().copied());
        let mut frame_at = Vec::new();
        for f in &frames {
            let p = l.push(f.position);
            l.push(f.rotation.iter().flatten().copied());
            l.push(f.jacobian.iter().flatten().copied());
            frame_at.push((f.name.clone(), p));
        }
        let program = Program::new(&d.graph, &l.outputs);
        let mut c = Checker::new(1e-9);
        for (s, sample) in reference.samples.iter().enumerate() {
            let v = run(
                &program,
                &map.to_ours(&sample.q),
                &map.to_ours(&sample.qd),
                &map.to_ours(&sample.qdd),
            );
            let o = &map.ours;
            for i in 0..n {
                for j in 0..n {
                    c.check(
                        || format!("{robot} #{s} M[{i}][{j}]"),
                        v[m_at + o[i] * n + o[j]],
                        sample.mass_matrix[i][j],
                    );
                    c.check(
                        || format!("{robot} #{s} C[{i}][{j}]"),
                        v[c_at + o[i] * n + o[j]],
                        sample.coriolis_matrix[i][j],
                    );
                }
                c.check(
                    || format!("{robot} #{s} g[{i}]"),
                    v[g_at + o[i]],
                    sample.gravity[i],
                );
                c.check(
                    || format!("{robot} #{s} b[{i}]"),
                    v[b_at + o[i]],
                    sample.bias[i],
                );
                c.check(
                    || format!("{robot} #{s} tau[{i}]"),
                    v[t_at + o[i]],
                    sample.tau[i],
                );
            }
            c.check(
                || format!("{robot} #{s} T"),
                v[ke_at],
                sample.kinetic_energy,
            );
            c.check(
                || format!("{robot} #{s} V"),
                v[pe_at],
                sample.potential_energy,
            );
            if let (Some(cf), Some(cp)) = (&sample.centrifugal, &sample.coriolis_pairs) {
                for i in 0..n {
                    for j in 0..n {
                        c.check(
                            || format!("{robot} #{s} Craig C[{i}][{j}]"),
                            v[cf_at + o[i] * n + o[j]],
                            cf[i][j],
                        );
                    }
                    let mut p = 0;
                    for a in 0..n {
                        for b in a + 1..n {
                            let ours = cp_at + o[i] * np + map.pair(a, b);
                            c.check(
                                || format!("{robot} #{s} Craig B[{i}][({a},{b})]"),
                                v[ours],
                                cp[i][p],
                            );
                            p += 1;
                        }
                    }
                }
            }
            assert_eq!(
                frame_at.len(),
                sample.frames.len(),
                "{robot}: one frame per URDF link"
            );
            for (name, at) in &frame_at {
                let f = &sample.frames[name];
                for k in 0..3 {
                    c.check(
                        || format!("{robot} #{s} {name} p[{k}]"),
                        v[at + k],
                        f.position[k],
                    );
                    for m in 0..3 {
                        c.check(
                            || format!("{robot} #{s} {name} R[{k}][{m}]"),
                            v[at + 3 + 3 * k + m],
                            f.rotation[k][m],
                        );
                    }
                }
                for r in 0..6 {
                    for j in 0..n {
                        let got = v[at + 12 + r * n + o[j]];
                        c.check(
                            || format!("{robot} #{s} {name} J[{r}][{j}]"),
                            got,
                            f.jacobian[r][j],
                        );
                    }
                }
            }
        }
        let sizes = format!(
            "{robot}: {} nodes, {} ops",
            d.graph.len(),
            program.ops().total()
        );
        println!("{sizes}; timings {:?}", d.timings);
        c.finish(robot);
    }
}

/// A deterministic pseudo-random stream in [-1, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn vec(&mut self, n: usize, scale: f64) -> Vec<f64> {
        (0..n).map(|_| scale * self.next()).collect()
    }
}

#[test]
fn physics_identities_hold_at_random_states() {
    let mut rng = Lcg(7);
    for robot in ROBOTS {
        let (_, mut d) = derive(robot);
        let n = d.dof;
        let lagrange = d.lagrange_equations();
        let mdot = d.mass_matrix_derivative();
        let mut l = Layout {
            outputs: Vec::new(),
        };
        let m_at = l.push(d.mass_matrix.iter().flatten().copied());
        let md_at = l.push(mdot.iter().flatten().copied());
        let c_at = l.push(d.coriolis_matrix.iter().flatten().copied());
        let tau_at = l.push(d.tau.iter().copied());
        let lag_at = l.push(lagrange.iter().copied());
        let g_at = l.push(d.gravity.iter().copied());
        let v_at = l.push([d.potential_energy]);
        let p = Program::new(&d.graph, &l.outputs);
        let mut c = Checker::new(1e-10);
        for _ in 0..5 {
            let (q, qd, qdd) = (rng.vec(n, 2.0), rng.vec(n, 2.0), rng.vec(n, 2.0));
            let v = run(&p, &q, &qd, &qdd);
            // Lagrange's equations from L = T - V give the same tau.
            for i in 0..n {
                c.check(
                    || format!("{robot} lagrange tau[{i}]"),
                    v[lag_at + i],
                    v[tau_at + i],
                );
            }
            // M symmetric positive definite: a Cholesky factorization succeeds.
            let m: Vec<Vec<f64>> = (0..n)
                .map(|i| v[m_at + i * n..m_at + (i + 1) * n].to_vec())
                .collect();
            let mut lower = vec![vec![0.0; n]; n];
            for i in 0..n {
                for j in 0..=i {
                    c.check(
                        || format!("{robot} M symmetric [{i}][{j}]"),
                        m[i][j],
                        m[j][i],
                    );
                    let s: f64 = m[i][j] - (0..j).map(|k| lower[i][k] * lower[j][k]).sum::<f64>();
                    if i == j {
                        assert!(s > 0.0, "{robot}: M not positive definite at pivot {i}");
                        lower[i][i] = s.sqrt();
                    } else {
                        lower[i][j] = s / lower[j][j];
                    }
                }
            }
            // dM/dt - 2C skew-symmetric.
            for i in 0..n {
                for j in 0..n {
                    let a = v[md_at + i * n + j] - 2.0 * v[c_at + i * n + j];
                    let b = v[md_at + j * n + i] - 2.0 * v[c_at + j * n + i];
                    c.check(|| format!("{robot} Mdot-2C skew [{i}][{j}]"), a, -b);
                }
            }
            // G = dV/dq by central differences of V.
            for i in 0..n {
                let h = 1e-6;
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[i] += h;
                qm[i] -= h;
                let fd =
                    (run(&p, &qp, &qd, &qdd)[v_at] - run(&p, &qm, &qd, &qdd)[v_at]) / (2.0 * h);
                let got = v[g_at + i];
                assert!(
                    (got - fd).abs() <= 1e-6 * got.abs().max(1.0),
                    "{robot} G[{i}] = {got}, dV/dq = {fd}"
                );
            }
            // C(q, 0) = 0.
            let zero = vec![0.0; n];
            let v0 = run(&p, &q, &zero, &qdd);
            for i in 0..n * n {
                c.check(|| format!("{robot} C(q, 0)[{i}]"), v0[c_at + i], 0.0);
            }
        }
        c.finish(robot);
    }
}

#[test]
fn recursive_algorithms_agree_with_the_lagrangian_route() {
    routes_agree(|_| ModelOptions::default());
}

/// The same with rotor inertia on every joint (0.1 + 0.01 i) and the URDFs' joint friction
/// (the Allegro hand has damping and Coulomb friction on every joint), smoothed: the fast
/// forms too, and forward dynamics inverting them.
#[test]
fn routes_agree_with_armature_and_friction() {
    routes_agree(|model| ModelOptions {
        armature: model
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.name.clone(), 0.1 + 0.01 * i as f64))
            .collect(),
        friction: true,
        coulomb_smoothing: 0.01,
        ..ModelOptions::default()
    });
}

/// Compares the Lagrangian and recursive routes, and the emitted fast forms, at random states
/// for the options `options(model with default options)` give.
fn routes_agree(options: impl Fn(&eomgen::model::Model) -> ModelOptions) {
    let mut rng = Lcg(11);
    for robot in ROBOTS {
        let (plain, _) = derive(robot);
        let model = eomgen::urdf::load_file(urdf_path(robot), &options(&plain)).expect("loads");
        let d = Derivation::new(&model);
        let n = d.dof;
        let r = &d.recursive;
        let mut l = Layout {
            outputs: Vec::new(),
        };
        let pairs: [(&str, Vec<Id>, Vec<Id>); 5] = [
            (
                "M",
                d.mass_matrix.iter().flatten().copied().collect(),
                r.mass_matrix.iter().flatten().copied().collect(),
            ),
            ("G", d.gravity.clone(), r.gravity.clone()),
            ("b", d.bias.clone(), r.bias.clone()),
            ("tau", d.tau.clone(), r.tau.clone()),
            (
                "C(q, qd)",
                d.coriolis_matrix.iter().flatten().copied().collect(),
                r.coriolis_matrix.iter().flatten().copied().collect(),
            ),
        ];
        let at: Vec<(usize, usize)> = pairs
            .iter()
            .map(|(_, a, b)| (l.push(a.iter().copied()), l.push(b.iter().copied())))
            .collect();
        let bg_at = l.push(r.bias_and_gravity.iter().copied());
        let fast_m_at = l.push(d.fast.mass_matrix.1.iter().flatten().copied());
        let fast_tau_at = l.push(d.fast.tau.1.iter().copied());
        let fd_at = l.push(d.fast.forward_dynamics.iter().copied());
        let b_at = at[2].0;
        let g_at = at[1].0;
        let p = Program::new(&d.graph, &l.outputs);
        let mut c = Checker::new(1e-10);
        for _ in 0..5 {
            let (q, qd, qdd) = (rng.vec(n, 2.0), rng.vec(n, 2.0), rng.vec(n, 2.0));
            let v = run_with_tau(&p, &q, &qd, &qdd, &vec![0.0; n]);
            // Forward dynamics with tau_in = the Lagrangian tau gives qdd back.
            let tau_in = v[at[3].0..at[3].0 + n].to_vec();
            let v_fd = run_with_tau(&p, &q, &qd, &qdd, &tau_in);
            for i in 0..n {
                c.check(
                    || format!("{robot} fast M/tau[{i}]"),
                    v[fast_tau_at + i],
                    v[at[3].0 + i],
                );
                c.check(
                    || format!("{robot} forward(inverse)[{i}]"),
                    v_fd[fd_at + i],
                    qdd[i],
                );
                for j in 0..n {
                    let k = i * n + j;
                    c.check(
                        || format!("{robot} fast M[{k}]"),
                        v[fast_m_at + k],
                        v[at[0].0 + k],
                    );
                }
            }
            for ((name, a, _), &(ia, ib)) in pairs.iter().zip(&at) {
                for k in 0..a.len() {
                    c.check(
                        || format!("{robot} {name}[{k}]: recursive vs Lagrangian"),
                        v[ib + k],
                        v[ia + k],
                    );
                }
            }
            for i in 0..n {
                c.check(
                    || format!("{robot} b+G[{i}]"),
                    v[bg_at + i],
                    v[b_at + i] + v[g_at + i],
                );
            }
        }
        c.finish(robot);
    }
}
