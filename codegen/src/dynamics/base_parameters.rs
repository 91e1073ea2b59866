//! Base parameters: a minimal set of linear combinations of the standard parameters that
//! determines the dynamics, each an exact formula (`ZZR_link1 = ZZ_link1 + YY_link2 + ...`).
//!
//! Two steps, as in Gautier and Khalil's method:
//!
//! 1. **Grouping rules** (exact, symbolic). A part of body `j`'s inertia that the joint's own
//!    motion leaves unchanged and that produces no effort along the joint's axis behaves as if
//!    welded to the parent: the kinetic and potential energies, hence the dynamics, do not
//!    change when it moves there. For a revolute joint with unit axis `s` (through the body
//!    origin, as in every URDF) that part is spanned by a point mass at the origin (`M`), a
//!    first moment along `s` and the inertia `I - s s^T`; for a prismatic joint, by any
//!    rotational inertia. From the leaves to the root, each body's part is moved to its parent
//!    (the root, which never moves, absorbs it) and one standard parameter per moved direction
//!    leaves the set: with a z axis, `M`, `MZ` and `YY` (`XXR = XX - YY`), exactly Khalil's
//!    rules; with a skewed axis, the same directions in the body's own axes.
//! 2. **What no motion can excite** (numeric rank on random states). The columns of the
//!    grouped parameters are evaluated at random states; a column that is zero (the inertia of
//!    a first body about axes other than its joint's, a first moment parallel to gravity) drops,
//!    and a column that is a combination of the columns before it (rare: rotor inertia on a
//!    first joint, parallel first joints with prismatic ones between) folds into those, with
//!    coefficients from a least-squares fit that reproduces it to rounding.
//!
//! The result is minimal: its count equals the rank of the full regressor over the sampled
//! states, which the tests check.

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector};

use crate::cas::{Graph, GraphFull, Id, Program, Symbol, SymbolKind};
use crate::kinematics::{joint, Params};
use crate::model::Model;
use crate::spatial::{M3, V3};

use super::newton_euler::{inertia_to_parent, LocalModel};
use super::regressor::{inertia_index, Owner, Parameter};

/// One base parameter.
#[derive(Clone, Debug)]
pub struct BaseParameter {
    /// The standard parameter it stands for (its regressor column is that one's), with `R`
    /// after its head when others are grouped into it: `ZZR_link1`.
    pub name: String,
    /// Index of that standard parameter, in regressor order.
    pub lead: usize,
    /// The combination of standard parameter symbols.
    pub formula: Id,
    /// Its value in generated code: the same combination of the parameters' values.
    pub value: Id,
}

/// A body's ten standard parameters as expressions, in [`BODY_PARAMETERS`] order.
type Ten = [Id; 10];

/// Step 1: the grouped parameters, as (index of the standard parameter whose column they
/// keep, combination of symbols), in regressor order.
fn grouped(
    g: &mut Graph,
    model: &Model,
    lm0: &LocalModel,
    parameters: &[Parameter],
) -> Vec<(usize, Id)> {
    let n = model.dof();
    let zero = g.zero();
    let mut acc: Vec<Ten> = vec![[zero; 10]; n];
    let mut kept_of_body: Vec<Vec<(usize, Id)>> = vec![Vec::new(); n];
    for p in parameters {
        if let Owner::Body { body, index } = p.owner {
            acc[body][index] = p.symbol;
        }
    }
    for j in (0..n).rev() {
        let v = acc[j];
        let (moved, pivots) = if joint::rotates(&model.joints[j]) {
            let axis = joint::axis(g, &model.joints[j]);
            let s = axis.map(|a| g.as_const(a).unwrap_or(0.0));
            revolute_part(g, &v, &s)
        } else {
            prismatic_part(g, &v)
        };
        for (index, &x) in v.iter().enumerate() {
            if !pivots.contains(&index) {
                let rest = g.sub(x, moved[index]);
                kept_of_body[j].push((index, rest));
            }
        }
        if let Some(parent) = model.joints[j].parent {
            let (m, h, jm) = unpack(&moved);
            let (h_p, j_p) = inertia_to_parent(g, lm0, j, Some(m), &h, &jm);
            let carried = pack(m, &h_p, &j_p);
            for k in 0..10 {
                acc[parent][k] = g.add(acc[parent][k], carried[k]);
            }
        }
    }
    let index_of = |owner: Owner| {
        parameters
            .iter()
            .position(|p| p.owner == owner)
            .expect("every body parameter is standard")
    };
    let mut out = Vec::new();
    for (body, kept) in kept_of_body.into_iter().enumerate() {
        for (index, formula) in kept {
            out.push((index_of(Owner::Body { body, index }), formula));
        }
    }
    for (k, p) in parameters.iter().enumerate() {
        if !matches!(p.owner, Owner::Body { .. }) {
            out.push((k, p.symbol));
        }
    }
    out
}

/// The index among `values` of the largest, the last one among equals (so that a z axis
/// keeps `XX` and moves `YY`, as Khalil's rules write it).
fn last_max(values: [f64; 3]) -> usize {
    let best = values.iter().copied().fold(f64::MIN, f64::max);
    (0..3)
        .rev()
        .find(|&k| values[k] >= best - 1e-12)
        .unwrap_or(2)
}

/// The part of `v` a revolute joint with unit axis `s` carries to its parent: `c1` of a point
/// mass at the origin, `c2` of a first moment along `s`, `c3` of the inertia `I - s s^T`, with
/// the three taken from one pivot entry each (the mass, the largest component of the first
/// moment along `s`, a diagonal inertia entry that `I - s s^T` does not leave small).
fn revolute_part(g: &mut Graph, v: &Ten, s: &[f64; 3]) -> (Ten, Vec<usize>) {
    let k = last_max(s.map(f64::abs));
    let p = last_max(s.map(|x| 1.0 - x * x));
    let pp = inertia_index(p, p);
    let c1 = v[0];
    let c2 = g.scale(v[1 + k], 1.0 / s[k]);
    let c3 = g.scale(v[pp], 1.0 / (1.0 - s[p] * s[p]));
    let mut moved = [g.zero(); 10];
    moved[0] = c1;
    for a in 0..3 {
        moved[1 + a] = g.scale(c2, s[a]);
        for b in a..3 {
            let e = f64::from(u8::from(a == b)) - s[a] * s[b];
            moved[inertia_index(a, b)] = g.scale(c3, e);
        }
    }
    // The pivots exactly: `c * (1 / s_k) * s_k` may round.
    moved[1 + k] = v[1 + k];
    moved[pp] = v[pp];
    (moved, vec![0, 1 + k, pp])
}

/// A prismatic joint carries its body's whole rotational inertia to its parent.
fn prismatic_part(g: &mut Graph, v: &Ten) -> (Ten, Vec<usize>) {
    let mut moved = [g.zero(); 10];
    moved[4..].copy_from_slice(&v[4..]);
    (moved, (4..10).collect())
}

fn unpack(v: &Ten) -> (Id, V3, M3) {
    let mut j = [[v[4]; 3]; 3];
    for (a, row) in j.iter_mut().enumerate() {
        for (b, e) in row.iter_mut().enumerate() {
            *e = v[inertia_index(a, b)];
        }
    }
    (v[0], [v[1], v[2], v[3]], j)
}

fn pack(m: Id, h: &V3, j: &M3) -> Ten {
    let mut v = [m; 10];
    v[1..4].copy_from_slice(h);
    for a in 0..3 {
        for b in a..3 {
            v[inertia_index(a, b)] = j[a][b];
        }
    }
    v
}

/// Relative size below which a sampled column counts as zero (against the largest column), and
/// relative residual below which it counts as a combination of the columns kept before it.
const ZERO_COLUMN: f64 = 1e-10;
const DEPENDENT: f64 = 1e-9;

/// Random states at which the grouped columns are compared: enough rows for twice the
/// columns.
fn sample_count(columns: usize, dof: usize) -> usize {
    2 * columns / dof.max(1) + 12
}

/// A small deterministic generator (the output must not depend on anything but the model).
struct Lcg(u64);

impl Lcg {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// The columns `ids` (N rows each, row-major per column) at random states, stacked: one
/// vector of `samples * N` numbers per column. Parameters take the model's values.
fn sampled_columns(
    g: &Graph,
    columns: &[Vec<Id>],
    params: &[(String, Id, f64)],
    dof: usize,
) -> Vec<DVector<f64>> {
    let outputs: Vec<Id> = columns.iter().flatten().copied().collect();
    let program = Program::new(g, &outputs);
    let values: HashMap<&str, f64> = params.iter().map(|(n, _, v)| (n.as_str(), *v)).collect();
    let samples = sample_count(columns.len(), dof);
    let mut rng = Lcg(0x5eed_1d3e_7f1f_a11e);
    let mut stacked = vec![DVector::zeros(samples * dof); columns.len()];
    for s in 0..samples {
        let state: Vec<[f64; 3]> = (0..dof)
            .map(|_| {
                [
                    rng.uniform(-3.0, 3.0),
                    rng.uniform(-2.0, 2.0),
                    rng.uniform(-2.0, 2.0),
                ]
            })
            .collect();
        let value = |sym: &Symbol| match sym.kind {
            SymbolKind::Q(i) => Some(state[i][0]),
            SymbolKind::Qd(i) => Some(state[i][1]),
            SymbolKind::Qdd(i) => Some(state[i][2]),
            SymbolKind::Tau(_) | SymbolKind::Force(_) => None,
            SymbolKind::Param => values.get(sym.name.as_str()).copied(),
        };
        let out = program
            .eval(value)
            .expect("regressor columns depend on the state and the model's parameters only");
        for (c, column) in stacked.iter_mut().enumerate() {
            for i in 0..dof {
                column[s * dof + i] = out[c * dof + i];
            }
        }
    }
    stacked
}

/// Step 2 on sampled columns: which columns to keep, and for each other non-zero column its
/// coefficients on the kept ones (`column = sum beta_k kept_k`).
#[allow(clippy::type_complexity)]
fn reduce(columns: &[DVector<f64>]) -> (Vec<usize>, Vec<(usize, Vec<f64>)>) {
    let largest = columns.iter().map(|c| c.norm()).fold(0.0, f64::max);
    let mut basis: Vec<DVector<f64>> = Vec::new();
    let mut kept = Vec::new();
    let mut dependent = Vec::new();
    for (k, c) in columns.iter().enumerate() {
        let norm = c.norm();
        if norm <= ZERO_COLUMN * largest {
            continue;
        }
        // Modified Gram-Schmidt, twice for orthogonality to rounding.
        let mut r = c.clone();
        for _ in 0..2 {
            for b in &basis {
                let d = b.dot(&r);
                r -= b * d;
            }
        }
        if r.norm() > DEPENDENT * norm {
            let unit = &r / r.norm();
            basis.push(unit);
            kept.push(k);
        } else {
            dependent.push(k);
        }
    }
    let rows = columns.first().map_or(0, |c| c.len());
    let a = DMatrix::from_fn(rows, kept.len(), |i, j| columns[kept[j]][i]);
    let svd = a.svd(true, true);
    let fits = dependent
        .into_iter()
        .map(|k| {
            let beta: Vec<f64> = svd
                .solve(&columns[k], 1e-14)
                .map(|b| b.iter().copied().collect())
                .unwrap_or_else(|_| vec![0.0; kept.len()]);
            let norm = columns[k].norm();
            let beta = beta
                .iter()
                .zip(&kept)
                .map(|(&b, &j)| clean(b, b.abs() * columns[j].norm() <= DEPENDENT * norm))
                .collect();
            (k, beta)
        })
        .collect();
    (kept, fits)
}

/// A fitted coefficient without its rounding: 0 when its term is negligible, the integer
/// when it is one to rounding (a rotor inertia folds into an inertia with coefficient 1).
fn clean(b: f64, negligible: bool) -> f64 {
    if negligible {
        0.0
    } else if (b - b.round()).abs() <= 1e-10 * b.abs().max(1.0) {
        b.round()
    } else {
        b
    }
}

/// The base parameters of `model`, from its standard `parameters` and `regressor` (N x P).
/// `params` are the derivation's symbolic parameters with the model's values (for sampling).
pub fn base_parameters(
    g: &mut Graph,
    model: &Model,
    params: &Params,
    parameters: &[Parameter],
    regressor: &[Vec<Id>],
) -> Result<Vec<BaseParameter>, GraphFull> {
    let n = model.dof();
    let zeros = vec![g.zero(); n];
    let lm0 = LocalModel::new(g, model, params, &zeros);
    let groups = grouped(g, model, &lm0, parameters);
    g.check()?;
    let columns: Vec<Vec<Id>> = groups
        .iter()
        .map(|&(lead, _)| regressor.iter().map(|row| row[lead]).collect())
        .collect();
    // One row per coordinate (fewer than joints with mimic joints).
    let sampled = sampled_columns(g, &columns, &params.symbols, regressor.len());
    let (kept, fits) = reduce(&sampled);
    let mut formulas: Vec<Id> = kept.iter().map(|&k| groups[k].1).collect();
    for (k, beta) in fits {
        for (slot, b) in formulas.iter_mut().zip(beta) {
            if b != 0.0 {
                *slot = g.sum(0.0, [(*slot, 1.0), (groups[k].1, b)]);
            }
        }
    }
    let to_values: HashMap<Id, Id> = parameters.iter().map(|p| (p.symbol, p.value)).collect();
    let values = g.substitute(&formulas, &to_values);
    g.check()?;
    Ok(kept
        .iter()
        .zip(formulas)
        .zip(values)
        .map(|((&k, formula), value)| {
            let lead = groups[k].0;
            let standard = &parameters[lead];
            let name = if formula == standard.symbol {
                standard.name.clone()
            } else {
                let (head, owner) = standard
                    .name
                    .split_once('_')
                    .unwrap_or((&standard.name, ""));
                format!("{head}R_{owner}")
            };
            BaseParameter {
                name,
                lead,
                formula,
                value,
            }
        })
        .collect())
}
