//! What the flags mean for the library: the model options and the `Builder` of the commands
//! that load a model, and the library's errors with the flag that raises a limit.

use std::path::Path;

use eomgen::{Builder, ModelOptions, SymbolicParams};

use super::defs::ModelArgs;
use crate::Failure;

impl ModelArgs {
    pub(crate) fn options(&self, symbolic: &Option<Vec<String>>) -> ModelOptions {
        // Every field, without `..Default::default()`: a new option has to be given a flag
        // (or a deliberate default) here.
        ModelOptions {
            gravity: self.gravity,
            joint_order: self.joint_order.clone(),
            symbolic: match symbolic {
                None => SymbolicParams::None,
                Some(v) if v.is_empty() => SymbolicParams::All,
                Some(v) => SymbolicParams::Links(v.clone()),
            },
            armature: self.armature.clone(),
            friction: self.friction,
            coulomb_smoothing: self.coulomb_smoothing,
            inertia_from_collision: self.density,
            repair_inertia: self.repair_inertia,
            floating_base: self.floating_base,
            contact_points: self.contacts.clone(),
            contact_frames: self.contact_frames.clone(),
            contact_points_at: self.contacts_at.clone(),
            passive_joints: self.passive.clone(),
            mimic_joints: self.mimic,
        }
    }

    /// A builder for `urdf` with these options and limits.
    pub(crate) fn builder(&self, urdf: &Path, symbolic: &Option<Vec<String>>) -> Builder {
        Builder::new(urdf)
            .model_options(self.options(symbolic))
            .max_dof(self.max_dof)
            .max_graph_nodes(self.max_graph_nodes)
    }
}

/// A library error, with the command-line flag that raises a limit instead of the Builder
/// option.
pub(crate) fn cli_error(e: eomgen::Error) -> Failure {
    match e {
        eomgen::Error::Limit {
            file,
            what,
            value,
            limit,
            raise,
        } => eomgen::Error::Limit {
            file,
            what,
            value,
            limit,
            raise: match raise {
                "Builder::max_dof" => "--max-dof",
                "Builder::max_graph_nodes" => "--max-graph-nodes",
                other => other,
            },
        }
        .into(),
        e => e.into(),
    }
}
