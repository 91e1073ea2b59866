//! The catalogue entries of contacts switched at run time: contact and impulse dynamics (and
//! their derivatives) with an `active: &[bool; C]` argument, one flag per contact (points,
//! then frames, as the generated `CONTACT_ROWS`), Baumgarte-stabilized contact dynamics, and
//! the contacts' world placements it reads. The same fixed-size results as the entries of all
//! contacts: an inactive contact's rows hold zero forces (impulses, derivatives), and the
//! accelerations are those of the robot generated with the active contacts alone.

use super::catalogue::{ActiveContacts, Evaluation, Input, Quantity, Shape};
use super::centroidal::quantity;
use super::Derivation;

/// What every entry says about its `active` argument.
const ACTIVE: &str = "`active[c]` switches contact `c` (points, then frames: `CONTACT_ROWS` gives each one's rows) on;";
const INACTIVE: &str = "an inactive contact's rows are zero and the rest is what the robot generated with the active contacts alone gives.";

/// The number of contacts of `d` (points, then frames).
fn contacts(d: &Derivation) -> usize {
    d.centroidal.contact_placements.len() / 12
}

/// `contact_placements`, `contact_forward_dynamics_active`, `contact_forward_dynamics_stabilized`
/// and `impulse_dynamics_active` (robots with contacts).
pub(super) fn quantities(d: &Derivation) -> Vec<Quantity> {
    let (n, k, c) = (d.dof, d.centroidal.contact_drift.len(), contacts(d));
    if k == 0 {
        return Vec::new();
    }
    let h = || d.fast.bias_gravity_friction.clone();
    let kkt = "then the runtime's sparse L^T D L of M and a Cholesky factorization of J_c M^-1 J_c^T, the inactive contacts' rows replaced by the identity's";
    vec![
        quantity(
            "contact_placements",
            &[Input::Q],
            Shape::Matrix(c, 12),
            &[
                "Each contact's world placement, one row per contact (points, then frames): the position",
                "(3), then the row-major rotation (9) of the contact frame (`eomgen_runtime::contact::placement`",
                "makes a `Pose` of a row). Pinocchio: `oMf` of the contact frames.",
            ],
            "forward kinematics to each contact frame",
            Evaluation::Exprs(d.centroidal.contact_placements.clone()),
        ),
        quantity(
            "contact_forward_dynamics_active",
            &[Input::Q, Input::Qd, Input::Tau],
            Shape::Vector(n + k),
            &[
                "`contact_forward_dynamics` with only the contacts of `active` held: Pinocchio's",
                "`constraintDynamics` with the models of the active contacts.",
                ACTIVE,
                INACTIVE,
                "No contact active: the forward dynamics without contacts.",
                "",
                "NaN in every entry when M(q) is not positive definite or the active rows of J_c are",
                "rank-deficient; `try_contact_forward_dynamics_active` says why.",
            ],
            &format!("M from `mass_matrix`, b + G by Newton-Euler, J_c and its drift, {kkt} (eomgen_runtime::contact::solve_factored_active_by, with the first half of the substitution unrolled too)"),
            Evaluation::ActiveContacts(ActiveContacts::Dynamics { h: h() }),
        ),
        quantity(
            "contact_forward_dynamics_stabilized",
            &[Input::Q, Input::Qd, Input::Tau],
            Shape::Vector(n + k),
            &[
                "`contact_forward_dynamics_active` with Baumgarte stabilization (`eomgen_runtime::Baumgarte`:",
                "gains and each contact's reference placement, given at run time): the constraint is",
                "`J_c qdd + Jdot_c qd = -kd J_c qd - kp e`, `e` the contacts' position (and, for frames,",
                "orientation) error in world axes, as Pinocchio's `RigidConstraintModel::corrector`.",
                ACTIVE,
                INACTIVE,
                "Gains zero: `contact_forward_dynamics_active`, to the bit. No derivatives: the",
                "`_derivatives` entries are those of the unstabilized constraint.",
                "",
                "NaN in every entry as `contact_forward_dynamics_active`; `try_contact_forward_dynamics_stabilized`",
                "says why.",
            ],
            "as `contact_forward_dynamics_active`, the drift corrected by `eomgen_runtime::Baumgarte::correct_drift` from `contact_placements`",
            Evaluation::ActiveContacts(ActiveContacts::Stabilized { h: h() }),
        ),
        quantity(
            "impulse_dynamics_active",
            &[Input::Q, Input::Qd],
            Shape::Vector(n + k),
            &[
                "`impulse_dynamics` at the contacts of `active` only: Pinocchio's `impulseDynamics` with",
                "the models of the active contacts.",
                ACTIVE,
                INACTIVE,
                "",
                "NaN in every entry as `impulse_dynamics`; `try_impulse_dynamics_active` says why.",
            ],
            &format!("M from `mass_matrix`, J_c from `contact_jacobian`, {kkt} (eomgen_runtime::impulse::solve_factored_active_by, with the first half of the substitution unrolled too)"),
            Evaluation::ActiveContacts(ActiveContacts::Impulse),
        ),
    ]
}

/// `contact_forward_dynamics_derivatives_active` and `impulse_dynamics_derivatives_active`
/// (robots with contacts and derivatives).
pub(super) fn derivatives(d: &Derivation) -> Vec<Quantity> {
    let (n, k) = (d.dof, d.centroidal.contact_drift.len());
    if k == 0 {
        return Vec::new();
    }
    vec![
        quantity(
            "contact_forward_dynamics_derivatives_active",
            &[Input::Q, Input::Qd, Input::Tau],
            Shape::Matrices(3, n + k, n),
            &[
                "`contact_forward_dynamics_derivatives` with only the contacts of `active` held (Pinocchio's",
                "`computeConstraintDynamicsDerivatives` with the models of the active contacts).",
                ACTIVE,
                INACTIVE,
                "",
                "NaN in every entry as `contact_forward_dynamics_active`;",
                "`try_contact_forward_dynamics_derivatives_active` says why.",
            ],
            "as `contact_forward_dynamics_derivatives`, the KKT system of the active contacts (eomgen_runtime::ContactKkt::new_active)",
            Evaluation::ActiveContacts(ActiveContacts::Derivatives {
                h: d.fast.bias_gravity_friction.clone(),
            }),
        ),
        quantity(
            "impulse_dynamics_derivatives_active",
            &[Input::Q, Input::Qd],
            Shape::Matrices(2, n + k, n),
            &[
                "`impulse_dynamics_derivatives` at the contacts of `active` only (Pinocchio's",
                "`computeImpulseDynamicsDerivatives` with the models of the active contacts).",
                ACTIVE,
                INACTIVE,
                "",
                "NaN in every entry as `impulse_dynamics_active`; `try_impulse_dynamics_derivatives_active`",
                "says why.",
            ],
            "as `impulse_dynamics_derivatives`, the KKT system of the active contacts (eomgen_runtime::ContactKkt::new_active)",
            Evaluation::ActiveContacts(ActiveContacts::ImpulseDerivatives),
        ),
    ]
}
