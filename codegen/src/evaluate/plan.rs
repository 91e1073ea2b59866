//! One plan per catalogue entry: the tapes it runs and how their numbers are composed, mirroring
//! what the entry's generated code does (straight-line code, a factorization at run time, a
//! loop over Christoffel columns).

use super::solve::{self, Factor, NotPositive};
use super::tape::{Binding, Tape};
use super::{EvalError, Layout};
use crate::cas::{Id, SymbolKind};
use crate::dynamics::{Craig, Derivation, Evaluation, Quantity};

/// How one quantity's numbers are made.
pub(super) enum Plan {
    /// Straight-line expressions.
    Exprs(Tape),
    /// Outputs, then pivots that must be positive (an unrolled factorization of `M`).
    Checked { tape: Tape, outputs: usize },
    /// `M^-1 (tau - h)`.
    Solve { m: Tape, h: Tape },
    /// `M^-1`.
    Inverse(Tape),
    /// Craig's matrices from `C(q, e_k)`, `k = 0..N`.
    Craig { coriolis: Tape, which: Craig },
    /// `(-M^-1 dtau/dq, -M^-1 dtau/dqd, M^-1)` at `qdd = FD(q, qd, tau)`.
    /// (`qdd = M^-1 (tau - h)` with `h` inverse dynamics at zero acceleration.)
    FdDerivatives { m: Tape, id: Tape, dtau: Tape },
    /// `(a, F)` with the contacts held.
    Contact {
        m: Tape,
        h: Tape,
        j: Tape,
        drift: Tape,
    },
}

/// The state, laid out as the tapes read it.
pub(super) struct Input<'a> {
    pub(super) layout: Layout,
    pub(super) values: &'a [f64],
}

impl Input<'_> {
    /// `tau - h` for `h` evaluated at this state (`b + G + F`).
    fn tau_minus(&self, h: &Tape) -> Vec<f64> {
        let at = self.layout.tau();
        let tau = &self.values[at..at + self.layout.nv];
        tau.iter()
            .zip(h.run(self.values))
            .map(|(t, h)| t - h)
            .collect()
    }

    /// The same state with the accelerations replaced.
    fn with_accelerations(&self, a: &[f64]) -> Vec<f64> {
        let mut v = self.values.to_vec();
        let at = self.layout.a();
        v[at..at + a.len()].copy_from_slice(a);
        v
    }
}

impl Plan {
    /// The plan of `q`; `find` gives the catalogue entries that run-time plans call.
    pub(super) fn new<'a>(
        d: &Derivation,
        layout: Layout,
        q: &Quantity,
        find: &dyn Fn(&str) -> Option<&'a Quantity>,
    ) -> Result<Plan, EvalError> {
        let tape = |ids: &[Id]| compile(d, layout, ids);
        let exprs_of = |name: &str| -> Result<Tape, EvalError> {
            match find(name).map(|q| &q.eval) {
                Some(Evaluation::Exprs(ids)) => tape(ids),
                _ => Err(EvalError::Internal(format!(
                    "`{name}` is not straight-line code"
                ))),
            }
        };
        let not = |why: &'static str| {
            Err(EvalError::NotEvaluable {
                name: q.name.to_string(),
                why,
            })
        };
        if q.inputs.contains(&crate::dynamics::Input::Forces) {
            return not("it takes contact forces besides the state");
        }
        Ok(match &q.eval {
            Evaluation::Exprs(ids) => Plan::Exprs(tape(ids)?),
            Evaluation::Factored { outputs, pivots }
            | Evaluation::ForwardDynamics {
                accelerations: outputs,
                pivots,
            }
            | Evaluation::ContactForwardDynamicsFlat { outputs, pivots } => {
                let all: Vec<Id> = outputs.iter().chain(pivots).copied().collect();
                Plan::Checked {
                    tape: tape(&all)?,
                    outputs: outputs.len(),
                }
            }
            Evaluation::ForwardDynamicsSolve { h } => Plan::Solve {
                m: exprs_of("mass_matrix")?,
                h: tape(h)?,
            },
            Evaluation::MassMatrixInverse => Plan::Inverse(exprs_of("mass_matrix")?),
            Evaluation::CraigColumns(which) => Plan::Craig {
                coriolis: exprs_of("coriolis_matrix")?,
                which: *which,
            },
            Evaluation::ForwardDynamicsDerivatives { .. } => Plan::FdDerivatives {
                m: exprs_of("mass_matrix")?,
                id: exprs_of("inverse_dynamics")?,
                dtau: exprs_of("inverse_dynamics_derivatives")?,
            },
            Evaluation::ContactForwardDynamics { h } => Plan::Contact {
                m: exprs_of("mass_matrix")?,
                h: tape(h)?,
                j: exprs_of("contact_jacobian")?,
                drift: exprs_of("contact_drift")?,
            },
            Evaluation::LinkPose
            | Evaluation::LinkJacobian
            | Evaluation::FrameMotion(_)
            | Evaluation::Integrate => {
                return not("it takes a link or a time step besides the state")
            }
            Evaluation::ImpulseDynamics
            | Evaluation::ImpulseDynamicsFlat { .. }
            | Evaluation::ImpulseDynamicsDerivatives => {
                return not("it takes a restitution besides the state")
            }
            Evaluation::ActiveContacts(_) => {
                return not("it takes the set of active contacts besides the state")
            }
            Evaluation::ContactDynamicsDerivatives { .. } => {
                return not("the evaluator does not compose the contact KKT derivatives yet")
            }
            Evaluation::Manifold(_) => {
                return not("it is the configuration space's geometry (eomgen_runtime::manifold)")
            }
        })
    }

    /// The quantity's numbers, row-major (tuples one matrix after the other).
    pub(super) fn run(&self, x: &Input) -> Result<Vec<f64>, NotPositive> {
        let n = x.layout.nv;
        let m_factor = |m: &Tape| {
            Factor::new(&m.run(x.values), n).map_err(|pivot| NotPositive {
                pivot,
                contact_space: false,
            })
        };
        match self {
            Plan::Exprs(t) => Ok(t.run(x.values)),
            Plan::Checked { tape, outputs } => {
                let mut v = tape.run(x.values);
                if let Some(pivot) = v[*outputs..]
                    .iter()
                    .position(|d| !d.is_finite() || *d <= 0.0)
                {
                    return Err(NotPositive {
                        pivot,
                        contact_space: false,
                    });
                }
                v.truncate(*outputs);
                Ok(v)
            }
            Plan::Solve { m, h } => {
                let rhs = x.tau_minus(h);
                Ok(m_factor(m)?.solve(&rhs))
            }
            Plan::Inverse(m) => Ok(m_factor(m)?.inverse()),
            Plan::Craig { coriolis, which } => Ok(craig(coriolis, x, *which)),
            Plan::FdDerivatives { m, id, dtau } => {
                let f = m_factor(m)?;
                let h = id.run(&x.with_accelerations(&vec![0.0; n]));
                let at = x.layout.tau();
                let rhs: Vec<f64> = (0..n).map(|i| x.values[at + i] - h[i]).collect();
                let qdd = f.solve(&rhs);
                let dtau = dtau.run(&x.with_accelerations(&qdd));
                // `d tau / d q`, then `d tau / d qd`: each n x n, solved in turn.
                let mut out: Vec<f64> = dtau
                    .chunks(n * n)
                    .flat_map(|b| f.solve_matrix(b, n))
                    .map(|v| -v)
                    .collect();
                out.extend(f.inverse());
                Ok(out)
            }
            Plan::Contact { m, h, j, drift } => {
                let rhs = x.tau_minus(h);
                let (a, f) = solve::contact(
                    &m.run(x.values),
                    &rhs,
                    &j.run(x.values),
                    &drift.run(x.values),
                )?;
                Ok(a.into_iter().chain(f).collect())
            }
        }
    }
}

/// A tape over the state's layout, parameters at their URDF values.
fn compile(d: &Derivation, layout: Layout, ids: &[Id]) -> Result<Tape, EvalError> {
    Tape::new(&d.graph, ids, layout.len(), |s| match s.kind {
        SymbolKind::Q(i) if i < layout.nq => Some(Binding::Input(i)),
        SymbolKind::Qd(i) if i < layout.nv => Some(Binding::Input(layout.v() + i)),
        SymbolKind::Qdd(i) if i < layout.nv => Some(Binding::Input(layout.a() + i)),
        SymbolKind::Tau(i) if i < layout.nv => Some(Binding::Input(layout.tau() + i)),
        SymbolKind::Param => d
            .params
            .iter()
            .find(|p| p.0 == s.name)
            .map(|p| Binding::Value(p.2)),
        _ => None,
    })
    .map_err(|symbol| EvalError::Internal(format!("no value for symbol `{symbol}`")))
}

/// Craig's centrifugal `C_ij = Gamma_ijj` or Coriolis `B_i,(j,k) = Gamma_ijk + Gamma_ikj`
/// (pairs `j < k` in the order (0,1), (0,2), ..., (1,2), ...) with `Gamma_ijk = C(q, e_k)_ij`.
fn craig(coriolis: &Tape, x: &Input, which: Craig) -> Vec<f64> {
    let n = x.layout.nv;
    let pairs = n * n.saturating_sub(1) / 2;
    let pair = |j: usize, k: usize| (0..j).map(|a| n - 1 - a).sum::<usize>() + (k - j - 1);
    let mut out = vec![
        0.0;
        if which == Craig::Centrifugal {
            n * n
        } else {
            n * pairs
        }
    ];
    for k in 0..n {
        let mut e = vec![0.0; n];
        e[k] = 1.0;
        let mut values = x.values.to_vec();
        let at = x.layout.v();
        values[at..at + n].copy_from_slice(&e);
        let c = coriolis.run(&values);
        for i in 0..n {
            match which {
                Craig::Centrifugal => out[n * i + k] = c[n * i + k],
                Craig::CoriolisPairs => {
                    for a in (0..n).filter(|&a| a != k) {
                        out[pairs * i + pair(a.min(k), a.max(k))] += c[n * i + a];
                    }
                }
            }
        }
    }
    out
}
