//! The symplectic integrators of `eomgen simulate` (`--integrator symplectic-euler`,
//! `implicit-midpoint`, `yoshida4`), on Hamilton's equations with the effort held over the
//! step: the runtime's `symplectic_euler_step`, `implicit_midpoint_step` and `yoshida4_step`
//! written again for a joint count known only at run time.
//!
//! `p = M(q) qd`; `pd = tau - h(q, qd) + (C + C^T) qd` with `h = b + G + F` and `C` the
//! Christoffel-form Coriolis matrix; the implicit equations are solved by fixed-point
//! iterations until the relative change is below `4 eps` or stops shrinking.

type Matrix = Vec<Vec<f64>>;
/// `M(q)`.
type MassFn<'a, E> = &'a dyn Fn(&[f64]) -> Result<Matrix, E>;
/// `pd(q, qd, tau)`.
type RateFn<'a, E> = &'a dyn Fn(&[f64], &[f64], &[f64]) -> Result<Vec<f64>, E>;
/// `x` with `M x = b`.
type SolveFn<'a, E> = &'a dyn Fn(&[Vec<f64>], &[f64]) -> Result<Vec<f64>, E>;

/// The dynamics a step needs, at a state: `M(q)`, the momentum rate `pd(q, qd, tau)`, and a
/// solver for `M x = b`.
pub struct System<'a, E> {
    pub mass: MassFn<'a, E>,
    pub rate: RateFn<'a, E>,
    pub solve: SolveFn<'a, E>,
}

/// A new position and velocity.
type Step<E> = Result<(Vec<f64>, Vec<f64>), E>;

/// Which method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    SymplecticEuler,
    ImplicitMidpoint,
    Yoshida4,
}

/// The most fixed-point iterations per implicit solve (as the runtime's
/// `FIXED_POINT_MAX_ITERATIONS`).
const MAX_ITERATIONS: usize = 50;

fn axpy(a: &[f64], h: f64, b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + h * y).collect()
}

fn mat_vec(m: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    m.iter()
        .map(|row| row.iter().zip(v).map(|(a, b)| a * b).sum())
        .collect()
}

/// `max |a - b| / max |a|` (the change itself when `a` is zero).
fn relative_change(a: &[f64], b: &[f64]) -> f64 {
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let s = a.iter().map(|x| x.abs()).fold(0.0, f64::max);
    if s > 0.0 {
        d / s
    } else {
        d
    }
}

fn converged(change: f64, previous: f64) -> bool {
    change <= 4.0 * f64::EPSILON || change >= previous || !change.is_finite()
}

/// One step of `method` from `(q, qd)` with effort `tau` held: the new `(q, qd)`.
pub fn step<E>(
    sys: &System<E>,
    method: Method,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    dt: f64,
) -> Step<E> {
    match method {
        Method::SymplecticEuler => symplectic_euler(sys, q, qd, tau, dt),
        Method::ImplicitMidpoint => implicit_midpoint(sys, q, qd, tau, dt),
        Method::Yoshida4 => {
            let cbrt2 = 2f64.cbrt();
            let w1 = 1.0 / (2.0 - cbrt2);
            let w0 = 1.0 - 2.0 * w1;
            let (q, qd) = implicit_midpoint(sys, q, qd, tau, w1 * dt)?;
            let (q, qd) = implicit_midpoint(sys, &q, &qd, tau, w0 * dt)?;
            implicit_midpoint(sys, &q, &qd, tau, w1 * dt)
        }
    }
}

fn symplectic_euler<E>(sys: &System<E>, q0: &[f64], qd0: &[f64], tau: &[f64], dt: f64) -> Step<E> {
    let m0 = (sys.mass)(q0)?;
    let p0 = mat_vec(&m0, qd0);
    let (mut p, mut qd) = (p0.clone(), qd0.to_vec());
    let mut previous = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let pd = (sys.rate)(q0, &qd, tau)?;
        let next = axpy(&p0, dt, &pd);
        let change = relative_change(&next, &p);
        p = next;
        qd = (sys.solve)(&m0, &p)?;
        if converged(change, previous) {
            break;
        }
        previous = change;
    }
    let q = axpy(q0, dt, &qd);
    let qd = (sys.solve)(&(sys.mass)(&q)?, &p)?;
    Ok((q, qd))
}

fn implicit_midpoint<E>(sys: &System<E>, q0: &[f64], qd0: &[f64], tau: &[f64], dt: f64) -> Step<E> {
    let half = 0.5 * dt;
    let p0 = mat_vec(&(sys.mass)(q0)?, qd0);
    let (mut qm, mut pm) = (q0.to_vec(), p0.clone());
    let mut qd = qd0.to_vec();
    let mut pd = (sys.rate)(q0, &qd, tau)?;
    let mut previous = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let (q_next, p_next) = (axpy(q0, half, &qd), axpy(&p0, half, &pd));
        let change = relative_change(&q_next, &qm).max(relative_change(&p_next, &pm));
        (qm, pm) = (q_next, p_next);
        qd = (sys.solve)(&(sys.mass)(&qm)?, &pm)?;
        pd = (sys.rate)(&qm, &qd, tau)?;
        if converged(change, previous) {
            break;
        }
        previous = change;
    }
    let q = axpy(q0, dt, &qd);
    let p = axpy(&p0, dt, &pd);
    let qd = (sys.solve)(&(sys.mass)(&q)?, &p)?;
    Ok((q, qd))
}
