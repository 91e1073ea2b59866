//! The parameters of a model in the graph: numbers, or symbols where the model asks for them.

use crate::cas::{Graph, Id};
use crate::model::Model;
use crate::spatial::{M3, V3};

/// The symbols and constants of a model's parameters, and where they come from.
#[derive(Clone, Debug)]
pub struct Params {
    /// Per body: mass, centre of mass (body frame), rotational inertia about the centre of mass.
    pub mass: Vec<Id>,
    pub com: Vec<V3>,
    pub inertia: Vec<M3>,
    /// Per joint: translation of the joint origin in the parent body frame.
    pub origin: Vec<V3>,
    /// Per joint: rotor inertia (armature), added to the mass matrix's diagonal.
    pub armature: Vec<Id>,
    /// Per joint: viscous damping and Coulomb friction coefficients (zero unless the model
    /// includes friction).
    pub damping: Vec<Id>,
    pub coulomb: Vec<Id>,
    /// The floating base's mass, centre of mass and inertia about it (numbers), when the model
    /// has one.
    pub base: Option<(Id, V3, M3)>,
    /// Every symbolic parameter: (symbol name, node, the URDF's value), in creation order.
    pub symbols: Vec<(String, Id, f64)>,
}

impl Params {
    /// Numbers from the model, or symbols where the model asks for them. A parameter whose URDF
    /// value is exactly zero stays a structural zero even when symbolic.
    pub fn new(g: &mut Graph, model: &Model) -> Params {
        let mut symbols = Vec::new();
        let mut value = |g: &mut Graph, symbolic: bool, name: String, v: f64| -> Id {
            if symbolic && v != 0.0 {
                let id = g.param(&name);
                symbols.push((name, id, v));
                id
            } else {
                g.constant(v)
            }
        };
        let (mut mass, mut com, mut inertia, mut origin) = (vec![], vec![], vec![], vec![]);
        for b in &model.bodies {
            let s = b.symbolic;
            let n = &b.name;
            mass.push(value(g, s, format!("m_{n}"), b.mass));
            com.push(
                [0, 1, 2].map(|k| value(g, s, format!("c{}_{n}", ["x", "y", "z"][k]), b.com[k])),
            );
            let mut i = [[g.zero(); 3]; 3];
            for r in 0..3 {
                for c in r..3 {
                    let axes = ["x", "y", "z"];
                    let id = value(
                        g,
                        s,
                        format!("I{}{}_{n}", axes[r], axes[c]),
                        b.inertia[(r, c)],
                    );
                    i[r][c] = id;
                    i[c][r] = id;
                }
            }
            inertia.push(i);
        }
        for j in &model.joints {
            let t = j.origin.translation;
            let s = j.symbolic_origin;
            let n = &j.name;
            origin
                .push([0, 1, 2].map(|k| value(g, s, format!("{}_{n}", ["x", "y", "z"][k]), t[k])));
        }
        // Joint parameters after every geometric one, so that adding them leaves the order of
        // existing fields alone; zero values stay structural zeros.
        let (mut armature, mut damping, mut coulomb) = (vec![], vec![], vec![]);
        for j in &model.joints {
            let (s, n) = (j.symbolic_origin, &j.name);
            armature.push(value(g, s, format!("Ia_{n}"), j.armature));
            let (d, f) = if model.include_friction {
                (j.damping, j.friction)
            } else {
                (0.0, 0.0)
            };
            damping.push(value(g, s, format!("damping_{n}"), d));
            coulomb.push(value(g, s, format!("friction_{n}"), f));
        }
        let base = model.base.as_ref().map(|b| {
            let com = [0, 1, 2].map(|k| g.constant(b.com[k]));
            let mut i = [[g.zero(); 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    i[r][c] = g.constant(b.inertia[(r.min(c), r.max(c))]);
                }
            }
            (g.constant(b.mass), com, i)
        });
        Params {
            base,
            mass,
            com,
            inertia,
            origin,
            armature,
            damping,
            coulomb,
            symbols,
        }
    }
}
