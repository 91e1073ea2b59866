//! Identification ([`Derivation::add_regressor`]): the joint torque regressor, the standard
//! parameters it multiplies, and the base parameters with their own regressor, as four
//! catalogue entries.

use crate::cas::{Graph, GraphFull, Id, Program, Style};
use crate::kinematics::const_v3;
use crate::model::Model;

use super::base_parameters::{base_parameters, BaseParameter};
use super::catalogue::{Evaluation, Home, Input, Quantity, Shape};
use super::newton_euler::JointTree;
use super::regressor::{self, standard_parameters, Parameter};
use super::{flat, Derivation};

/// The regressor and the parameters of a derivation (with [`Derivation::add_regressor`]).
#[derive(Clone, Debug)]
pub struct Identification {
    /// The standard parameters, in regressor column order.
    pub parameters: Vec<Parameter>,
    /// How the regressor is computed, one sentence.
    pub route: &'static str,
    /// `Y(q, qd, qdd)`, N x P: `tau = Y pi`.
    pub regressor: Vec<Vec<Id>>,
    /// The base parameters, in base regressor column order.
    pub base: Vec<BaseParameter>,
    /// The base regressor: the columns of the base parameters' leads (by the cheaper route
    /// for them), and how it is computed.
    pub base_regressor: Vec<Vec<Id>>,
    pub base_route: &'static str,
    /// The URDF name of each body (the child link of joint `i`), in joint order.
    pub body_names: Vec<String>,
}

impl Identification {
    /// A base parameter's formula in standard parameter symbols, its lead first and the others
    /// in regressor order: `ZZ_link1 + YY_link2 + 0.0625*M_link2`. Terms whose numeric
    /// coefficient is below `noise` (rounding of the geometry) are left out.
    pub fn formula(&self, g: &mut Graph, b: &BaseParameter, style: Style, noise: f64) -> String {
        let mut order: Vec<usize> = (0..self.parameters.len()).collect();
        order.retain(|&k| k != b.lead);
        order.insert(0, b.lead);
        let mut text = String::new();
        for k in order {
            let p = &self.parameters[k];
            let coefficient = g.diff(b.formula, p.symbol);
            let (negative, magnitude) = match g.as_const(coefficient) {
                Some(c) if c.abs() <= noise => continue,
                Some(c) => (c < 0.0, g.constant(c.abs())),
                None => (false, coefficient),
            };
            let term = g.mul(magnitude, p.symbol);
            let printed = g.print(term, style);
            text.push_str(match (text.is_empty(), negative) {
                (true, false) => "",
                (true, true) => "-",
                (false, false) => " + ",
                (false, true) => " - ",
            });
            text.push_str(&printed);
        }
        if text.is_empty() {
            text.push('0');
        }
        text
    }
}

impl Derivation {
    /// Adds identification to the catalogue: `regressor` and `parameters` (the standard
    /// parameters, see [`super::regressor`]), `base_regressor` and `base_parameters` (see
    /// [`super::base_parameters`]). Fails when the graph fills.
    pub fn add_regressor(&mut self, model: &Model) -> Result<(), GraphFull> {
        let g = &mut self.graph;
        // The joint tree's regressor at the joints' coordinates, projected onto the robot's
        // (`G^T Y`: unchanged without mimic joints, see `coupling`).
        let JointTree { params, map, lm } = JointTree::new(g, model, &self.q);
        let (joint_qd, joint_qdd) = (map.rates(g, &self.qd), map.rates(g, &self.qdd));
        let grav = const_v3(g, &model.gravity);
        let parameters = standard_parameters(g, model, &lm, &params);
        let inputs = regressor::Inputs {
            model,
            lm: &lm,
            params: &params,
            parameters: &parameters,
            qd: &joint_qd,
            qdd: &joint_qdd,
            gravity: grav,
        };
        let projected = regressor::projected(g, &inputs)?;
        let differentiated = regressor::differentiated(g, &inputs)?;
        let routes = [
            (PROJECTED, map.project_rows(g, &projected)),
            (DIFFERENTIATED, map.project_rows(g, &differentiated)),
        ];
        let (route, y) = cheapest(g, &routes, |y| y.to_vec());
        let base = base_parameters(g, model, &params, &parameters, &y)?;
        let keep = |y: &[Vec<Id>]| -> Vec<Vec<Id>> {
            y.iter()
                .map(|row| base.iter().map(|b| row[b.lead]).collect())
                .collect()
        };
        let (base_route, base_regressor) = cheapest(g, &routes, keep);
        let id = Identification {
            parameters,
            route,
            regressor: y,
            base_route,
            base_regressor,
            base,
            body_names: model.bodies.iter().map(|b| b.name.clone()).collect(),
        };
        let extra = quantities(&mut self.graph, &id);
        self.quantities.extend(extra);
        self.identification = Some(id);
        Ok(())
    }
}

const STATE: &[Input] = &[Input::Q, Input::Qd, Input::Qdd];

/// The regressor's two routes (see [`super::regressor`]): whichever has fewer operations.
const PROJECTED: &str = "Route: each joint's motion subspace carried down to the bodies below it, dotted with their 6 x 10 body regressors.";
const DIFFERENTIATED: &str = "Route: Newton-Euler with every standard parameter a symbol, differentiated in each (each body's 6 x 10 regressor carried up to its ancestors).";

/// The route whose `pick` of the regressor has the fewest operations, and that pick.
fn cheapest(
    g: &Graph,
    routes: &[(&'static str, Vec<Vec<Id>>)],
    pick: impl Fn(&[Vec<Id>]) -> Vec<Vec<Id>>,
) -> (&'static str, Vec<Vec<Id>>) {
    let mut best: Option<(usize, &'static str, Vec<Vec<Id>>)> = None;
    for (route, y) in routes {
        let picked = pick(y);
        let cost = Program::new(g, &flat(&picked)).ops().total();
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, route, picked));
        }
    }
    let (_, route, y) = best.expect("at least one route");
    (route, y)
}

/// The four entries.
fn quantities(g: &mut Graph, id: &Identification) -> Vec<Quantity> {
    let n = id.regressor.len();
    let (p, pb) = (id.parameters.len(), id.base.len());
    let base_doc = base_parameters_doc(g, id);
    vec![
        Quantity {
            name: "regressor",
            inputs: STATE,
            shape: Shape::Matrix(n, p),
            home: Home::Inherent,
            doc: regressor_doc(n, p),
            route: id.route.into(),
            eval: Evaluation::Exprs(flat(&id.regressor)),
        },
        Quantity {
            name: "parameters",
            inputs: &[],
            shape: Shape::Vector(p),
            home: Home::Inherent,
            doc: vec![
                "The standard parameters that `regressor` multiplies, from the URDF (or from the struct's".into(),
                "fields when symbolic): names in `PARAMETER_NAMES`.".into(),
            ],
            route: "Route: m, m c and I_c + m (|c|^2 1 - c c^T) per body.".into(),
            eval: Evaluation::Exprs(id.parameters.iter().map(|x| x.value).collect()),
        },
        Quantity {
            name: "base_regressor",
            inputs: STATE,
            shape: Shape::Matrix(n, pb),
            home: Home::Inherent,
            doc: vec![
                format!("The regressor of the {pb} base parameters: `inverse_dynamics = Y_b base_parameters()`;"),
                "the columns of `regressor` named in `BASE_PARAMETER_NAMES`, full column rank over the".into(),
                "robot's states: what least squares on measured torques identifies.".into(),
            ],
            route: id.base_route.into(),
            eval: Evaluation::Exprs(flat(&id.base_regressor)),
        },
        Quantity {
            name: "base_parameters",
            inputs: &[],
            shape: Shape::Vector(pb),
            home: Home::Inherent,
            doc: base_doc,
            route: "Route: Khalil's grouping rules generalized to any joint axis (exact), then the columns no motion can excite dropped by rank on random states.".into(),
            eval: Evaluation::Exprs(id.base.iter().map(|b| b.value).collect()),
        },
    ]
}

/// The regressor's documentation, for `n` joints and `p` standard parameters.
fn regressor_doc(n: usize, p: usize) -> Vec<String> {
    let extras = if p > 10 * n {
        format!(
            " Then {} joint coefficient(s) (rotor inertia `IA`, viscous `FV` and Coulomb `FS` friction).",
            p - 10 * n
        )
    } else {
        String::new()
    };
    vec![
        "The joint torque regressor Y(q, qd, qdd): `inverse_dynamics = Y parameters()`, row `i`".into(),
        "joint `i`, column `k` standard parameter `k` (`PARAMETER_NAMES`). Ten per body (`BODY_NAMES`),".into(),
        "m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz, with the centre of mass c and the".into(),
        format!("inertia about the origin of the body's frame (its joint's child link frame), in its axes.{extras}"),
    ]
}

/// `base_parameters`' documentation: what they are, then each as its formula.
fn base_parameters_doc(g: &mut Graph, id: &Identification) -> Vec<String> {
    let style = Style {
        digits: Some(6),
        ..Style::default()
    };
    let mut doc = vec![
        format!("The {} base parameters: a minimal set of combinations of the standard parameters that", id.base.len()),
        "determines the dynamics (`tau = base_regressor(q, qd, qdd) base_parameters()`), named in".into(),
        "`BASE_PARAMETER_NAMES` after the standard parameter whose column they keep (`R` when others".into(),
        "are grouped into it).".into(),
        String::new(),
        "Each as its combination of standard parameters (`PARAMETER_NAMES`; coefficients to 6"
            .into(),
        "significant digits here, exact in the code):".into(),
        String::new(),
    ];
    for b in &id.base {
        let f = id.formula(g, b, style, 1e-12);
        doc.push(format!("- `{} = {}`", b.name, f));
    }
    doc
}

/// The `PARAMETER_NAMES` and `BASE_PARAMETER_NAMES` of an identification.
pub fn names(id: &Identification) -> (Vec<String>, Vec<String>) {
    (
        id.parameters.iter().map(|p| p.name.clone()).collect(),
        id.base.iter().map(|b| b.name.clone()).collect(),
    )
}
