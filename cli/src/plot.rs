//! The plots of `eomgen simulate`: which figures a run gives (positions, velocities, efforts,
//! energy; a floating base's position and contact forces), assembled from its outcome and
//! drawn by `figure.rs`.

mod figure;

use std::path::{Path, PathBuf};

use figure::Figure;
pub use figure::Format;

use crate::{simulate, simulate_floating};
use eomgen::model::Model;

/// The title of the energy plot: whether the run should conserve energy.
fn energy_title(
    name: &str,
    integrator: &str,
    controlled: bool,
    dissipative: bool,
    dt: f64,
) -> String {
    match (controlled, dissipative) {
        (true, _) => format!("{name}: energy (controlled run: not conserved by design)"),
        (false, true) => format!("{name}: energy (damped run: not conserved by design)"),
        (false, false) => format!("{name}: energy drift of {integrator} (dt = {dt} s)"),
    }
}

/// The plots of a fixed-base run: positions to `path`, velocities, efforts and energy beside.
pub(crate) fn fixed_plots(
    path: &Path,
    model: &Model,
    o: &simulate::Options,
    out: &simulate::Outcome,
) -> Result<(), String> {
    let name = &model.name;
    // One series per coordinate: with mimic joints, the independent joints.
    let joints = model.coordinate_joints();
    let names: Vec<String> = joints
        .iter()
        .map(|&j| model.joints[j].name.clone())
        .collect();
    let rotating: Vec<bool> = joints
        .iter()
        .map(|&j| model.joints[j].kind.is_revolute())
        .collect();
    let controlled = o.controller != simulate::Controller::None;
    let (energy, series, y_label) = figure::energy_drift(&out.energy);
    let figure = |title: String, y_label: String, names: Vec<String>, values| figure::Figure {
        title,
        y_label,
        names,
        times: &out.times,
        values,
    };
    let efforts = if controlled {
        format!("{name}: joint efforts of the controller")
    } else {
        format!("{name}: joint efforts (no controller: none applied)")
    };
    figure::write_all(&[
        (
            path.to_path_buf(),
            figure(
                format!("{name}: joint positions"),
                format!("position ({})", figure::unit(&rotating, "rad", "m")),
                names.clone(),
                &out.positions,
            ),
        ),
        (
            figure::sibling(path, "velocities"),
            figure(
                format!("{name}: joint velocities"),
                format!("velocity ({})", figure::unit(&rotating, "rad/s", "m/s")),
                names.clone(),
                &out.velocities,
            ),
        ),
        (
            figure::sibling(path, "efforts"),
            figure(
                efforts,
                format!("effort ({})", figure::unit(&rotating, "N m", "N")),
                names,
                &out.efforts,
            ),
        ),
        (
            figure::sibling(path, "energy"),
            figure(
                energy_title(name, o.integrator.name(), controlled, out.dissipative, o.dt),
                y_label.to_string(),
                vec![series.to_string()],
                &energy,
            ),
        ),
    ])
}

/// The plots of a floating-base run: the base position to `path`; beside it the vertical
/// contact forces, the joint positions, the velocities and efforts (the joints', or the
/// base's without joints) and the energy.
pub(crate) fn floating_plots(
    path: &Path,
    model: &Model,
    o: &simulate_floating::Options,
    out: &simulate_floating::Outcome,
) -> Result<(), String> {
    let name = &model.name;
    let nj = out.joints.first().map_or(0, Vec::len);
    let joints: Vec<String> = model
        .joints
        .iter()
        .take(nj)
        .map(|j| j.name.clone())
        .collect();
    let rotating: Vec<bool> = model
        .joints
        .iter()
        .take(nj)
        .map(|j| j.kind.is_revolute())
        .collect();
    let nv = 6 + nj;
    let controlled = o.controller != simulate_floating::Controller::None;
    let (energy, series, energy_label) = figure::energy_drift(&out.energy);
    let base_v = figure::columns(&out.velocities, 0..3);
    let joint_v = figure::columns(&out.velocities, 6..nv);
    let base_f = figure::columns(&out.efforts, 0..3);
    let joint_f = figure::columns(&out.efforts, 6..nv);
    let figure = |title, y_label, names, values| titled(title, y_label, names, &out.times, values);
    let mut figures = vec![(
        path.to_path_buf(),
        figure(
            format!("{name}: base position"),
            "position (m)",
            xyz(""),
            &out.base,
        ),
    )];
    if !model.contacts.is_empty() {
        let feet = model
            .contacts
            .iter()
            .map(|&f| model.frames[f].name.clone())
            .collect();
        figures.push((
            figure::sibling(path, "forces"),
            figure(
                format!("{name}: vertical contact forces"),
                "vertical force (N)",
                feet,
                &out.forces,
            ),
        ));
    }
    let motion = Motion {
        joints: &joints,
        positions: &out.joints,
        rotating: &rotating,
        columns: [&base_v, &joint_v, &base_f, &joint_f],
        controlled,
    };
    figures.extend(motion.figures(path, name, &out.times));
    figures.push((
        figure::sibling(path, "energy"),
        figure(
            energy_title(name, "RK4", controlled, out.dissipative, o.dt),
            energy_label,
            vec![series.to_string()],
            &energy,
        ),
    ));
    figure::write_all(&figures)
}

/// The velocities and efforts of a floating-base run, `columns` = [base velocity, joint
/// velocities, base force, joint efforts]: the joints' when it has joints, else the base's
/// (its force only when controlled).
struct Motion<'a> {
    joints: &'a [String],
    /// The joint positions.
    positions: &'a [Vec<f64>],
    rotating: &'a [bool],
    columns: [&'a Vec<Vec<f64>>; 4],
    controlled: bool,
}

impl<'a> Motion<'a> {
    /// The figures, beside `path`, of the robot `name`.
    fn figures(&self, path: &Path, name: &str, times: &'a [f64]) -> Vec<(PathBuf, Figure<'a>)> {
        let figure = |title, y_label, names, values| titled(title, y_label, names, times, values);
        let [base_v, joint_v, base_f, joint_f] = self.columns;
        let mut out = Vec::new();
        if !self.joints.is_empty() {
            let unit = |a, l| figure::unit(self.rotating, a, l);
            out.extend([
                (
                    figure::sibling(path, "joints"),
                    figure(
                        format!("{name}: joint positions"),
                        &format!("position ({})", unit("rad", "m")),
                        self.joints.to_vec(),
                        self.positions,
                    ),
                ),
                (
                    figure::sibling(path, "velocities"),
                    figure(
                        format!("{name}: joint velocities"),
                        &format!("velocity ({})", unit("rad/s", "m/s")),
                        self.joints.to_vec(),
                        joint_v,
                    ),
                ),
                (
                    figure::sibling(path, "efforts"),
                    figure(
                        format!("{name}: joint efforts"),
                        &format!("effort ({})", unit("N m", "N")),
                        self.joints.to_vec(),
                        joint_f,
                    ),
                ),
            ]);
        } else {
            out.push((
                figure::sibling(path, "velocities"),
                figure(
                    format!("{name}: base linear velocity (base axes)"),
                    "velocity (m/s)",
                    xyz("v"),
                    base_v,
                ),
            ));
            if self.controlled {
                out.push((
                    figure::sibling(path, "efforts"),
                    figure(
                        format!("{name}: force on the base (base axes)"),
                        "force (N)",
                        xyz("f"),
                        base_f,
                    ),
                ));
            }
        }
        out
    }
}

/// The `x`, `y`, `z` series names after `prefix`.
fn xyz(prefix: &str) -> Vec<String> {
    ["x", "y", "z"].map(|c| format!("{prefix}{c}")).to_vec()
}

/// A figure of `values` against `times`.
fn titled<'a>(
    title: String,
    y_label: &str,
    names: Vec<String>,
    times: &'a [f64],
    values: &'a [Vec<f64>],
) -> Figure<'a> {
    Figure {
        title,
        y_label: y_label.to_string(),
        names,
        times,
        values,
    }
}
