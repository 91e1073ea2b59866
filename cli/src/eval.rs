//! `eomgen eval`: the derived quantities at one numeric state, through the CAS interpreter.

use std::fmt::Write as _;

use eomgen::cas::{format_number, Id, SymbolKind};
use eomgen::dynamics::Derivation;
use eomgen::model::Model;

/// A state and the input torque.
pub struct State {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
}

/// Everything `eval` prints.
pub struct Values {
    pub mass_matrix: Vec<Vec<f64>>,
    pub bias: Vec<f64>,
    pub gravity: Vec<f64>,
    pub tau: Vec<f64>,
    /// The joint friction effort `F(qd)`, zero unless the model includes friction.
    pub friction: Vec<f64>,
    pub qdd: Vec<f64>,
    pub kinetic_energy: f64,
    pub potential_energy: f64,
}

/// Solves `M x = rhs` by Cholesky; `Err(k)` when pivot `k` (0-based) is not positive, that is
/// when `M` is not positive definite.
pub fn cholesky_solve(m: &[Vec<f64>], rhs: &[f64]) -> Result<Vec<f64>, usize> {
    let n = rhs.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                // NaN is not finite either.
                if !s.is_finite() || s <= 0.0 {
                    return Err(i);
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = vec![0.0; n];
    for i in 0..n {
        y[i] = (rhs[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        x[i] = (y[i] - (i + 1..n).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    Ok(x)
}

/// Evaluates expressions of the derivation at `s` (parameters at their URDF values).
pub fn evaluate_ids(d: &Derivation, s: &State, outputs: &[Id]) -> Result<Vec<f64>, String> {
    d.graph
        .eval(outputs, |sym| match sym.kind {
            SymbolKind::Q(i) => s.q.get(i).copied(),
            SymbolKind::Qd(i) => s.qd.get(i).copied(),
            SymbolKind::Qdd(i) => s.qdd.get(i).copied(),
            SymbolKind::Param => d.params.iter().find(|p| p.0 == sym.name).map(|p| p.2),
            // No other symbol appears in M, b, G, C, tau or the energies.
            #[allow(unreachable_patterns)]
            _ => None,
        })
        .map_err(|e| format!("internal error while evaluating: {e}"))
}

/// Evaluates the derivation at `s` (parameters at their URDF values).
pub fn evaluate(model: &Model, d: &Derivation, s: &State) -> Result<Values, String> {
    let n = d.dof;
    let mut outputs: Vec<_> = d.mass_matrix.iter().flatten().copied().collect();
    outputs.extend(&d.bias);
    outputs.extend(&d.gravity);
    outputs.extend(&d.tau);
    outputs.extend(&d.friction);
    outputs.push(d.kinetic_energy);
    outputs.push(d.potential_energy);
    let v = evaluate_ids(d, s, &outputs)?;
    let mass_matrix: Vec<Vec<f64>> = v[..n * n].chunks(n).map(|r| r.to_vec()).collect();
    let bias = v[n * n..n * n + n].to_vec();
    let gravity = v[n * n + n..n * n + 2 * n].to_vec();
    let tau = v[n * n + 2 * n..n * n + 3 * n].to_vec();
    let friction = v[n * n + 3 * n..n * n + 4 * n].to_vec();
    let rhs: Vec<f64> = (0..n)
        .map(|i| s.tau[i] - bias[i] - gravity[i] - friction[i])
        .collect();
    let qdd = cholesky_solve(&mass_matrix, &rhs).map_err(|k| {
        format!(
            "{}: the mass matrix is not positive definite at this state (pivot {} of {n}, joint \
             `{}`): check the masses and inertias",
            model.name,
            k + 1,
            model.coordinate_names()[k]
        )
    })?;
    Ok(Values {
        mass_matrix,
        bias,
        gravity,
        tau,
        friction,
        qdd,
        kinetic_energy: v[n * n + 4 * n],
        potential_energy: v[n * n + 4 * n + 1],
    })
}

fn list(v: &[f64], digits: Option<usize>) -> String {
    let items: Vec<String> = v.iter().map(|&x| format_number(x, digits)).collect();
    format!("[{}]", items.join(", "))
}

/// The text `eval` prints.
pub fn print(model: &Model, s: &State, v: &Values, digits: Option<usize>) -> String {
    let names = model.coordinate_names();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} degrees of freedom; joint order: {}",
        model.name,
        names.len(),
        names.join(", ")
    );
    let _ = writeln!(out, "q = {}", list(&s.q, digits));
    let _ = writeln!(out, "qd = {}", list(&s.qd, digits));
    let _ = writeln!(out, "qdd = {}", list(&s.qdd, digits));
    let _ = writeln!(out, "tau_in = {}", list(&s.tau, digits));
    let _ = writeln!(out, "\nmass matrix M(q):");
    for row in &v.mass_matrix {
        let _ = writeln!(out, "  {}", list(row, digits));
    }
    let _ = writeln!(out, "bias b(q, qd) = {}", list(&v.bias, digits));
    let _ = writeln!(out, "gravity G(q) = {}", list(&v.gravity, digits));
    let f = if model.include_friction {
        let _ = writeln!(out, "friction F(qd) = {}", list(&v.friction, digits));
        " + F"
    } else {
        ""
    };
    let _ = writeln!(
        out,
        "inverse dynamics tau = M qdd + b + G{f} = {}",
        list(&v.tau, digits)
    );
    let f = if model.include_friction { " - F" } else { "" };
    let _ = writeln!(
        out,
        "forward dynamics qdd = M^-1 (tau_in - b - G{f}) = {}",
        list(&v.qdd, digits)
    );
    let _ = writeln!(
        out,
        "kinetic energy T = {}",
        format_number(v.kinetic_energy, digits)
    );
    let _ = writeln!(
        out,
        "potential energy V = {}",
        format_number(v.potential_energy, digits)
    );
    out
}

#[cfg(test)]
mod tests {
    use super::cholesky_solve;

    #[test]
    fn solves_positive_definite_systems() {
        let m = vec![
            vec![4.0, 2.0, 0.4],
            vec![2.0, 3.0, 0.5],
            vec![0.4, 0.5, 2.0],
        ];
        let x = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| m[i][j] * x[j]).sum())
            .collect();
        let y = cholesky_solve(&m, &b).unwrap();
        for i in 0..3 {
            assert!((y[i] - x[i]).abs() < 1e-14);
        }
    }

    #[test]
    fn reports_the_failing_pivot() {
        // Indefinite: the second pivot is 1 - 4 < 0.
        let m = vec![vec![1.0, 2.0], vec![2.0, 1.0]];
        assert_eq!(cholesky_solve(&m, &[1.0, 1.0]), Err(1));
        let singular = vec![vec![0.0, 0.0], vec![0.0, 1.0]];
        assert_eq!(cholesky_solve(&singular, &[1.0, 1.0]), Err(0));
        let nan = vec![vec![f64::NAN]];
        assert_eq!(cholesky_solve(&nan, &[1.0]), Err(0));
    }
}
