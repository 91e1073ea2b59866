//! The catalogue of generated quantities: one [`Quantity`] per generated function, with its
//! name, arguments, result shape, documentation, route and expressions.
//!
//! Emission ([`crate::emit`]), `eomgen eval` and the tests loop over the catalogue, so adding a
//! quantity is one entry in `quantities.rs` (its `catalogue` function) plus the function that derives its
//! expressions. See `docs/architecture.md`.

use crate::cas::{Graph, Id, OpCount, Program};

/// An argument of a generated function: a vector of joint-space values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Input {
    /// Joint positions `q`.
    Q,
    /// Joint velocities `qd`.
    Qd,
    /// Joint accelerations `qdd`.
    Qdd,
    /// Joint efforts `tau`.
    Tau,
    /// Contact forces (K, the contact rows), read by the symbols of `Graph::force`.
    Forces,
}

impl Input {
    /// The argument's name in generated code.
    pub fn name(self) -> &'static str {
        match self {
            Input::Q => "q",
            Input::Qd => "qd",
            Input::Qdd => "qdd",
            Input::Tau => "tau",
            Input::Forces => "forces",
        }
    }
}

/// The shape of a quantity's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// One number.
    Scalar,
    /// A vector of this length.
    Vector(usize),
    /// Rows x columns, row-major.
    Matrix(usize, usize),
    /// A tuple of this many rows x columns matrices, one after the other.
    Matrices(usize, usize, usize),
}

impl Shape {
    /// How many numbers the value holds.
    pub fn len(self) -> usize {
        match self {
            Shape::Scalar => 1,
            Shape::Vector(n) => n,
            Shape::Matrix(r, c) => r * c,
            Shape::Matrices(k, r, c) => k * r * c,
        }
    }

    /// True for an empty vector or matrix.
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }
}

/// Where a generated function lives: a runtime trait's impl, or the generated type's inherent
/// impl. A trait is implemented only when a selection keeps all of its methods
/// ([`select`]); otherwise they are inherent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Home {
    /// A method of the runtime's `Dynamics` trait (fixed base).
    Dynamics,
    /// A method of the runtime's `FloatingDynamics` trait (floating base).
    FloatingDynamics,
    /// A method of the runtime's `Contacts` trait (floating base with contact points); of
    /// `contact_forward_dynamics`, the trait holds its `try_` variant.
    Contacts,
    /// An inherent method of the generated type only.
    Inherent,
}

impl Home {
    /// The runtime traits a quantity can live in.
    pub const TRAITS: [Home; 3] = [Home::Dynamics, Home::FloatingDynamics, Home::Contacts];
}

/// Craig's two velocity-product matrices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Craig {
    /// Centrifugal `C(q)`, N x N.
    Centrifugal,
    /// Coriolis `B(q)`, N x N(N-1)/2.
    CoriolisPairs,
}

/// How generated code evaluates a quantity.
#[derive(Clone, Debug)]
pub enum Evaluation {
    /// Straight-line code for these expressions (row-major for a matrix).
    Exprs(Vec<Id>),
    /// A loop over the `N` Christoffel columns `C(q, e_k)` of `coriolis_matrix`: a few lines of
    /// code instead of `N^3 / 2` flattened entries, for robots where flattening does not pay.
    CraigColumns(Craig),
    /// `qdd = M^-1 (tau - b - G - F)` by an unrolled sparse `L^T D L` solve: the accelerations
    /// and the factorization's pivots (checked at run time).
    ForwardDynamics {
        accelerations: Vec<Id>,
        pivots: Vec<Id>,
    },
    /// The same solve at run time: `M` from `mass_matrix`, `h = b + G + F` as straight-line
    /// code, then the sparse `L^T D L` over the joint tree (unrolled for the robot, as
    /// `tree::ltdl_factor` and `tree::ltdl_substitute` do it at run time), for
    /// robots whose unrolled solve (and second copy of `M`) would be large.
    ForwardDynamicsSolve { h: Vec<Id> },
    /// A link frame's world pose: per-joint transforms composed along the link's chain.
    LinkPose,
    /// A link frame's 6 x N Jacobian, from the same per-joint transforms.
    LinkJacobian,
    /// `M^-1`: `M` from `mass_matrix`, factorized by the unrolled tree `L^T D L`, then
    /// `L^-1 D^-1 L^-T` unrolled over the tree too (`tree::ltdl_inverse_factored`'s operations;
    /// `emit::tree_solve`).
    MassMatrixInverse,
    /// Straight-line expressions that hold when every pivot of the unrolled `L^T D L`
    /// factorization of `M` is positive (checked at run time: NaN in every entry otherwise).
    Factored { outputs: Vec<Id>, pivots: Vec<Id> },
    /// `(d qdd/dq, d qdd/dqd, M^-1)` at run time: `d tau/dq` and `d tau/dqd` at
    /// `qdd = FD(q, qd, tau)` and the tree `L^T D L` factors of `M`, either from
    /// `forward_dynamics_partials` (`partials`: one straight-line body) or from `mass_matrix`
    /// factorized at run time, `inverse_dynamics(q, qd, 0)` and `inverse_dynamics_derivatives`;
    /// then `-M^-1` times both (`tree::ltdl_substitute_rows`), and `M^-1` from the same factors,
    /// unrolled over the tree (`tree::ltdl_inverse_factored`'s operations; `emit::tree_solve`).
    ForwardDynamicsDerivatives { partials: bool },
    /// The accelerations and contact forces with the contact points held, solved at run time:
    /// `M` from `mass_matrix`, `h = b + G + F` straight-line, `J_c` and its drift from
    /// `contact_jacobian` and `contact_drift` (`eomgen_runtime::contact::solve`).
    ContactForwardDynamics { h: Vec<Id> },
    /// The accelerations (`N`) and contact forces (`K`) with the contacts held, as one
    /// straight-line program that holds when its pivots (`M`'s, then `J_c M^-1 J_c^T`'s) are
    /// positive (`contact_flat`).
    ContactForwardDynamicsFlat { outputs: Vec<Id>, pivots: Vec<Id> },
    /// A floating base's `q (+) v dt` (`eomgen_runtime::free_flyer::integrate`).
    Integrate,
    /// A link frame's velocity, acceleration or Jacobian time variation, walked along its
    /// chain at run time (`eomgen_runtime::frame`).
    FrameMotion(super::FrameMotion),
    /// `difference` or a Jacobian of `integrate` or `difference` (`eomgen_runtime::manifold`).
    Manifold(super::Manifold),
    /// The derivatives of the contact forward dynamics, solved at run time: `h` straight-line,
    /// then `eomgen_runtime::ContactKkt` from `mass_matrix` and `contact_jacobian`, the
    /// accelerations and forces, `inverse_dynamics_derivatives` there and
    /// `contact_dynamics_partials`.
    ContactDynamicsDerivatives { h: Vec<Id> },
    /// The velocity after an impact and the contact impulses, solved at run time
    /// (`eomgen_runtime::ContactKkt::impulse` from `mass_matrix` and `contact_jacobian`).
    ImpulseDynamics,
    /// `ImpulseDynamics` at restitution zero as one straight-line program (`contact_flat`):
    /// the velocity change (`N`) and impulses (`K`), which the restitution scales, and the
    /// pivots (`M`'s, then `J_c M^-1 J_c^T`'s).
    ImpulseDynamicsFlat { outputs: Vec<Id>, pivots: Vec<Id> },
    /// The derivatives of `ImpulseDynamics`, from `impulse_dynamics_partials`.
    ImpulseDynamicsDerivatives,
    /// Contact or impulse dynamics (or their derivatives) with a set of active contacts given
    /// at run time (`eomgen_runtime::contact::row_mask`, `ContactKkt::new_active`).
    ActiveContacts(ActiveContacts),
}

/// The entries of [`Evaluation::ActiveContacts`]: each the entry of all contacts it extends,
/// with an `active: &[bool; C]` argument after its inputs.
#[derive(Clone, Debug)]
pub enum ActiveContacts {
    /// `contact_forward_dynamics_active`: `h` straight-line as `ContactForwardDynamics`.
    Dynamics { h: Vec<Id> },
    /// `contact_forward_dynamics_stabilized`: the same with an `eomgen_runtime::Baumgarte`
    /// argument, from `contact_placements`.
    Stabilized { h: Vec<Id> },
    /// `contact_forward_dynamics_derivatives_active`.
    Derivatives { h: Vec<Id> },
    /// `impulse_dynamics_active`.
    Impulse,
    /// `impulse_dynamics_derivatives_active`.
    ImpulseDerivatives,
}

/// How the entries of a printed quantity are indexed and named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// One number (`T`).
    Scalar,
    /// `N` entries (`G1`).
    Vector,
    /// `N x N`, symmetric: the upper triangle is printed (`M12`).
    Symmetric,
    /// `N x N` (`C12`).
    Square,
    /// Craig's `N x N(N-1)/2`, a row per joint and a column per pair `j < k` (`B1_23`).
    Pairs,
    /// `N x N` partial derivatives of joint efforts in joint positions (`dtau1/dq2`).
    Partials,
}

/// How people name and write a quantity: its generated method's name (its one name
/// everywhere), the symbols printed by `eomgen show` and accepted as aliases by every command,
/// the heading and definition of its printed section, and the expressions printed (the
/// readable closed forms, which may differ from the route generated code takes).
///
/// [`NOTATIONS`](super::quantities::NOTATIONS) lists them; `show --term`, `eval`, the command
/// line's help, `Builder::quantities` and the reports read it.
#[derive(Clone, Copy, Debug)]
pub struct Notation {
    /// The generated method's name.
    pub name: &'static str,
    /// The symbol in plain text, the prefix of printed entries (`M` gives `M12`).
    pub text: &'static str,
    /// The symbol in LaTeX (`\tau` gives `\tau_{1}`).
    pub latex: &'static str,
    /// Other names accepted for it: textbook symbols and earlier names.
    pub aliases: &'static [&'static str],
    /// The heading of its printed section.
    pub title: &'static str,
    /// The sentence under the heading, or empty.
    pub definition: &'static str,
    /// How its entries are indexed.
    pub layout: Layout,
    /// The expressions printed, row-major (`None`: not derived for this robot).
    pub(crate) printed: fn(&super::Derivation) -> Option<Vec<Id>>,
}

impl Notation {
    /// Whether `s` names this quantity: its name or one of its aliases (case matters: `B` and
    /// `b` differ).
    pub fn is_named(&self, s: &str) -> bool {
        self.name == s || self.aliases.contains(&s)
    }

    /// The title's name and symbol, before its defining formula if it has one: what
    /// `eomgen eval` prints before the quantity's value.
    ///
    /// ```
    /// use eomgen::catalogue::notation;
    /// assert_eq!(notation("b").unwrap().label(), "Bias b(q, qd)");
    /// assert_eq!(notation("M").unwrap().label(), "Mass matrix M(q)");
    /// ```
    pub fn label(&self) -> &'static str {
        self.title.split(" = ").next().unwrap_or(self.title)
    }
}

pub use super::quantities::NOTATIONS;

/// The notation of the quantity named `s` (its name or an alias).
pub fn notation(s: &str) -> Option<&'static Notation> {
    NOTATIONS.iter().find(|n| n.is_named(s))
}

/// The generated name of the quantity named `s` (a name or an alias); `s` itself when no
/// notation has it.
pub fn canonical(s: &str) -> &str {
    notation(s).map_or(s, |n| n.name)
}

/// One generated function.
#[derive(Clone, Debug)]
pub struct Quantity {
    /// The function's name in generated code (and in `Builder::quantities`).
    pub name: &'static str,
    /// Its joint-space arguments, in order.
    pub inputs: &'static [Input],
    /// The result's shape.
    pub shape: Shape,
    /// The trait or the inherent impl.
    pub home: Home,
    /// What it is: documentation lines, the first a one-line summary.
    pub doc: Vec<String>,
    /// How it is computed, one sentence.
    pub route: String,
    /// The expressions, or the kernel, generated code evaluates.
    pub eval: Evaluation,
}

impl Quantity {
    /// How people write it, when it has symbols ([`Notation`]).
    pub fn notation(&self) -> Option<&'static Notation> {
        NOTATIONS.iter().find(|n| n.name == self.name)
    }

    /// The expressions a straight-line body evaluates (for a forward dynamics, the
    /// accelerations and then the pivots); empty for loop kernels.
    pub fn exprs(&self) -> Vec<Id> {
        match &self.eval {
            Evaluation::Exprs(e) => e.clone(),
            Evaluation::ForwardDynamics {
                accelerations,
                pivots,
            } => accelerations.iter().chain(pivots).copied().collect(),
            Evaluation::ForwardDynamicsSolve { h }
            | Evaluation::ContactForwardDynamics { h }
            | Evaluation::ContactDynamicsDerivatives { h }
            | Evaluation::ActiveContacts(
                ActiveContacts::Dynamics { h }
                | ActiveContacts::Stabilized { h }
                | ActiveContacts::Derivatives { h },
            ) => h.clone(),
            Evaluation::Factored { outputs, pivots }
            | Evaluation::ContactForwardDynamicsFlat { outputs, pivots }
            | Evaluation::ImpulseDynamicsFlat { outputs, pivots } => {
                outputs.iter().chain(pivots).copied().collect()
            }
            _ => Vec::new(),
        }
    }

    /// The operation count of its straight-line body (zero for loop kernels).
    pub fn ops(&self, g: &Graph) -> OpCount {
        Program::new(g, &self.exprs()).ops()
    }

    /// Quantities whose generated code this one calls (or, for a straight-line contact
    /// forward dynamics, brings with it).
    pub fn needs(&self) -> &'static [&'static str] {
        use ActiveContacts as A;
        match self.eval {
            Evaluation::CraigColumns(_) => &["coriolis_matrix"],
            Evaluation::ForwardDynamicsSolve { .. } | Evaluation::MassMatrixInverse => {
                &["mass_matrix"]
            }
            Evaluation::ContactForwardDynamics { .. }
            | Evaluation::ActiveContacts(A::Dynamics { .. }) => {
                &["mass_matrix", "contact_jacobian", "contact_drift"]
            }
            // Calls neither, but brings them as the run-time route does: with them the
            // `Contacts` trait is complete, as a selection of it alone has always had.
            Evaluation::ContactForwardDynamicsFlat { .. } => &["contact_jacobian", "contact_drift"],
            Evaluation::ImpulseDynamicsFlat { .. } => &["mass_matrix", "contact_jacobian"],
            Evaluation::ActiveContacts(A::Stabilized { .. }) => &[
                "mass_matrix",
                "contact_jacobian",
                "contact_drift",
                "contact_placements",
            ],
            Evaluation::ContactDynamicsDerivatives { .. }
            | Evaluation::ActiveContacts(A::Derivatives { .. }) => &[
                "mass_matrix",
                "contact_jacobian",
                "contact_drift",
                "inverse_dynamics_derivatives",
                "contact_dynamics_partials",
            ],
            Evaluation::ImpulseDynamics | Evaluation::ActiveContacts(A::Impulse) => {
                &["mass_matrix", "contact_jacobian"]
            }
            Evaluation::ImpulseDynamicsDerivatives
            | Evaluation::ActiveContacts(A::ImpulseDerivatives) => &[
                "mass_matrix",
                "contact_jacobian",
                "impulse_dynamics_partials",
            ],
            Evaluation::ForwardDynamicsDerivatives { partials: true } => {
                &["forward_dynamics_partials"]
            }
            Evaluation::ForwardDynamicsDerivatives { partials: false } => &[
                "mass_matrix",
                "inverse_dynamics",
                "inverse_dynamics_derivatives",
            ],
            _ => &[],
        }
    }
}

/// The names of a catalogue, in order.
pub fn names(quantities: &[Quantity]) -> Vec<&'static str> {
    quantities.iter().map(|q| q.name).collect()
}

/// Keeps the quantities named in `wanted` and everything they need, transitively (a need of a
/// need too), in catalogue order; `Err` with the first unknown name.
/// A runtime trait is implemented only with all its methods: when the selection leaves some
/// of a trait's out, the ones kept become inherent ([`Home::Inherent`]).
pub fn select(quantities: Vec<Quantity>, wanted: &[String]) -> Result<Vec<Quantity>, String> {
    if let Some(bad) = wanted
        .iter()
        .find(|w| !quantities.iter().any(|q| q.name == w.as_str()))
    {
        return Err(bad.clone());
    }
    // The closure of `wanted` under `needs`: a worklist, each name visited once.
    let mut keep: Vec<&str> = Vec::new();
    let mut todo: Vec<&str> = wanted.iter().map(String::as_str).collect();
    while let Some(name) = todo.pop() {
        if keep.contains(&name) {
            continue;
        }
        keep.push(name);
        if let Some(q) = quantities.iter().find(|q| q.name == name) {
            todo.extend(q.needs());
        }
    }
    let count = |qs: &[Quantity], home| qs.iter().filter(|q| q.home == home).count();
    let all = Home::TRAITS.map(|h| count(&quantities, h));
    let mut kept: Vec<Quantity> = quantities
        .into_iter()
        .filter(|q| keep.contains(&q.name))
        .collect();
    for (home, all) in Home::TRAITS.into_iter().zip(all) {
        if count(&kept, home) < all {
            for q in kept.iter_mut().filter(|q| q.home == home) {
                q.home = Home::Inherent;
            }
        }
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quantity(name: &'static str, eval: Evaluation) -> Quantity {
        Quantity {
            name,
            inputs: &[Input::Q],
            shape: Shape::Scalar,
            home: Home::Inherent,
            doc: Vec::new(),
            route: String::new(),
            eval,
        }
    }

    /// The catalogue's order of a large robot's entries that call each other at run time.
    fn catalogue() -> Vec<Quantity> {
        vec![
            quantity("mass_matrix", Evaluation::Exprs(Vec::new())),
            quantity("gravity", Evaluation::Exprs(Vec::new())),
            quantity("inverse_dynamics", Evaluation::Exprs(Vec::new())),
            quantity(
                "forward_dynamics",
                Evaluation::ForwardDynamicsSolve { h: Vec::new() },
            ),
            quantity(
                "inverse_dynamics_derivatives",
                Evaluation::Exprs(Vec::new()),
            ),
            quantity("mass_matrix_inverse", Evaluation::MassMatrixInverse),
            quantity("forward_dynamics_partials", Evaluation::Exprs(Vec::new())),
            quantity(
                "forward_dynamics_derivatives",
                Evaluation::ForwardDynamicsDerivatives { partials: true },
            ),
            quantity(
                "forward_dynamics_derivatives_composed",
                Evaluation::ForwardDynamicsDerivatives { partials: false },
            ),
            quantity("centrifugal", Evaluation::CraigColumns(Craig::Centrifugal)),
            quantity("coriolis_matrix", Evaluation::Exprs(Vec::new())),
        ]
    }

    fn selected(wanted: &[&str]) -> Vec<&'static str> {
        let wanted: Vec<String> = wanted.iter().map(|w| w.to_string()).collect();
        names(&select(catalogue(), &wanted).unwrap())
    }

    #[test]
    fn the_needs_are_selected() {
        // `forward_dynamics_derivatives` calls `forward_dynamics_partials` alone, which computes
        // its own `M` and accelerations: not `mass_matrix`, `inverse_dynamics` or
        // `mass_matrix_inverse`.
        assert_eq!(
            selected(&["forward_dynamics_derivatives"]),
            ["forward_dynamics_partials", "forward_dynamics_derivatives"]
        );
        // Composed from the run-time factorization: `mass_matrix`, `inverse_dynamics` and
        // `inverse_dynamics_derivatives`, not `forward_dynamics` or `mass_matrix_inverse`.
        assert_eq!(
            selected(&["forward_dynamics_derivatives_composed"]),
            [
                "mass_matrix",
                "inverse_dynamics",
                "inverse_dynamics_derivatives",
                "forward_dynamics_derivatives_composed",
            ]
        );
        // A need later in the catalogue than the quantity that calls it.
        assert_eq!(
            selected(&["centrifugal"]),
            ["centrifugal", "coriolis_matrix"]
        );
        assert_eq!(
            selected(&["forward_dynamics"]),
            ["mass_matrix", "forward_dynamics"]
        );
        assert_eq!(
            selected(&["mass_matrix_inverse"]),
            ["mass_matrix", "mass_matrix_inverse"]
        );
    }

    #[test]
    fn the_selection_is_in_catalogue_order_whatever_the_order_asked() {
        let order = ["mass_matrix", "gravity", "mass_matrix_inverse"];
        assert_eq!(selected(&["mass_matrix_inverse", "gravity"]), order);
        assert_eq!(
            selected(&["gravity", "mass_matrix_inverse", "gravity"]),
            order
        );
    }

    #[test]
    fn a_trait_keeps_its_methods_only_when_all_are_selected() {
        let mut all = catalogue();
        for q in all.iter_mut().take(3) {
            q.home = Home::Dynamics;
        }
        let some = select(all.clone(), &["gravity".to_string()]).unwrap();
        assert!(some.iter().all(|q| q.home == Home::Inherent));
        let every = ["mass_matrix", "gravity", "inverse_dynamics"].map(String::from);
        let kept = select(all, &every).unwrap();
        assert!(kept.iter().all(|q| q.home == Home::Dynamics));
    }

    #[test]
    fn names_and_symbols_are_one_quantity() {
        assert_eq!(canonical("tau"), "inverse_dynamics");
        assert_eq!(canonical("M"), "mass_matrix");
        assert_eq!(canonical("coriolis"), "coriolis_matrix");
        assert_eq!(canonical("mass_matrix"), "mass_matrix");
        assert_eq!(canonical("link_pose"), "link_pose");
        // Every name and alias is one quantity's only.
        let mut seen = Vec::new();
        for n in NOTATIONS.iter() {
            for s in std::iter::once(n.name).chain(n.aliases.iter().copied()) {
                assert!(!seen.contains(&s), "`{s}` names two quantities");
                seen.push(s);
            }
        }
    }

    #[test]
    fn an_unknown_name_is_returned() {
        let wanted = ["gravity".to_string(), "mass_matrx".to_string()];
        assert_eq!(select(catalogue(), &wanted).unwrap_err(), "mass_matrx");
    }
}
