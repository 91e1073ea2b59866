//! The base parameters for people (`eomgen show --base-parameters`): each as its exact
//! combination of standard parameters, in text, LaTeX or Markdown.
//!
//! ```
//! use eomgen::report::{print_base_parameters, ShowOptions};
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm">
//!     <inertial>
//!       <origin xyz="0 0 -0.5"/> <mass value="2"/>
//!       <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/>
//!     </inertial>
//!   </link>
//!   <joint name="swing" type="continuous">
//!     <parent link="base"/> <child link="arm"/> <axis xyz="0 1 0"/>
//!   </joint>
//! </robot>"#;
//! let derived = eomgen::Builder::from_urdf_str(urdf, "pendulum.urdf")
//!     .regressor()
//!     .derived()
//!     .unwrap();
//! let text = print_base_parameters(&derived, &ShowOptions::default()).unwrap();
//! // Swinging about y under gravity along z: YY (about the pivot) and the first moments
//! // across the axis, MX and MZ.
//! assert!(text.contains("  MX_arm = MX_arm\n"));
//! assert!(text.contains("  YY_arm = YY_arm\n"));
//! assert!(text.contains("3 base parameters"));
//! ```

use std::collections::BTreeSet;
use std::fmt::Write as _;

use crate::cas::{format_number, Id};
use crate::dynamics::regressor::Owner;
use crate::dynamics::{Derivation, Identification};
use crate::model::Model;

use super::document::{describe_param, kind_name, value_source, vec3};
use super::latex::{align, aligned, tex_escape};
use super::markdown::md_escape;
use super::style_of;
use super::{Format, ReportError, ShowOptions};

/// Numeric coefficients at most this large are rounding noise of the geometry and are not
/// printed (generated code keeps them).
const NOISE: f64 = 1e-12;

/// Prints each base parameter of `d` (which needs [`Derivation::add_regressor`]) as its
/// combination of standard parameters, with its value from the URDF, the joints, the standard
/// parameters that have no effect at all, and a legend. Honours the format, digits, source
/// and standalone options of `opts`; its terms, entry and form do not apply.
#[doc(hidden)]
pub fn render_base_parameters(
    model: &Model,
    d: &Derivation,
    opts: &ShowOptions,
) -> Result<String, ReportError> {
    let Some(id) = &d.identification else {
        return Err(ReportError::InvalidEntry {
            entry: "base parameters".into(),
            reason: "need the regressor: derive with Derivation::add_regressor".into(),
        });
    };
    let style = style_of(opts);
    let mut g = d.graph.clone();
    let formulas: Vec<(String, String)> = id
        .base
        .iter()
        .map(|b| {
            let name = g.param(&b.name);
            (g.print(name, style), id.formula(&mut g, b, style, NOISE))
        })
        .collect();
    let numeric: Vec<Id> = id.base.iter().map(|b| b.value).collect();
    let values: Vec<(String, String)> = id
        .base
        .iter()
        .zip(&numeric)
        .map(|(b, &v)| {
            let name = g.param(&b.name);
            (g.print(name, style), g.print(v, style))
        })
        .collect();
    let used: BTreeSet<Id> = g
        .reachable(&id.base.iter().map(|b| b.formula).collect::<Vec<_>>())
        .into_iter()
        .collect();
    let idle: Vec<String> = id
        .parameters
        .iter()
        .filter(|p| !used.contains(&p.symbol))
        .map(|p| p.name.clone())
        .collect();
    let geometry: Vec<(String, String)> = d
        .params
        .iter()
        .filter(|p| used.contains(&p.1))
        .map(|(name, sym, v)| {
            let what = format!(
                "{} ({} {})",
                describe_param(name),
                value_source(name),
                format_number(*v, None)
            );
            (g.print(*sym, style), what)
        })
        .collect();

    let intro = intro(model, d, id, &idle, opts);
    let legend = legend(id, geometry);
    let joints = joint_lines(model, id, opts);
    let doc = Document {
        title: format!("{}: base parameters", model.name),
        intro,
        joints,
        formulas,
        values,
        legend,
    };
    Ok(match opts.format {
        Format::Text => doc.text(),
        Format::Latex => doc.latex(opts.standalone),
        Format::Markdown => doc.markdown(),
    })
}

/// The introduction: the robot, how many base parameters of how many, how numbers are printed,
/// and the standard parameters without effect (`idle`).
fn intro(
    model: &Model,
    d: &Derivation,
    id: &Identification,
    idle: &[String],
    opts: &ShowOptions,
) -> Vec<String> {
    let (p, pb) = (id.parameters.len(), id.base.len());
    let numbers = match opts.digits {
        Some(k) => format!("{k} significant digits"),
        None => "shortest exact decimals".to_string(),
    };
    let source = opts.source.as_deref().unwrap_or("URDF");
    let mut intro = vec![
        format!(
            "{} ({source}): {} degrees of freedom, gravity {} m/s^2.",
            model.name,
            d.dof,
            vec3(&model.gravity, opts.digits)
        ),
        format!(
            "{pb} base parameters of {p} standard parameters: tau = Y_b(q, qd, qdd) pi_b, with Y_b \
             the columns of the regressor Y that they keep, of full rank; {pb} is the rank of Y."
        ),
        format!(
            "Each is an exact combination of standard parameters (numbers are the geometry's, \
             printed with {numbers})."
        ),
    ];
    if !idle.is_empty() {
        intro.push(format!(
            "No effect on the dynamics (in no combination): {}.",
            idle.join(", ")
        ));
    }
    intro
}

/// The legend: the standard parameters' names, and the geometry's symbols (`geometry`).
fn legend(id: &Identification, geometry: Vec<(String, String)>) -> Vec<(String, String)> {
    let mut legend: Vec<(String, String)> = vec![
        (
            "M_b, MX_b, MY_b, MZ_b".into(),
            "mass and first moment m c of body b (the child link of its joint, fixed children \
             merged), in its frame"
                .into(),
        ),
        (
            "XX_b, XY_b, XZ_b, YY_b, YZ_b, ZZ_b".into(),
            "inertia of body b about its frame's origin, in its axes".into(),
        ),
    ];
    let has = |f: fn(&Owner) -> bool| id.parameters.iter().any(|p| f(&p.owner));
    if has(|o| matches!(o, Owner::Armature(_))) {
        legend.push(("IA_j".into(), "rotor inertia (armature) of joint j".into()));
    }
    if has(|o| matches!(o, Owner::Viscous(_))) {
        legend.push((
            "FV_j, FS_j".into(),
            "viscous and Coulomb friction coefficients of joint j".into(),
        ));
    }
    legend.push((
        "XR_b".into(),
        "a base parameter that keeps the column of X_b, with other parameters grouped into it"
            .into(),
    ));
    legend.extend(geometry);
    legend
}

/// One line per coordinate; a mimic joint is described with the coordinate it follows.
fn joint_lines(model: &Model, id: &Identification, opts: &ShowOptions) -> Vec<String> {
    let describe = |i: usize| {
        let j = &model.joints[i];
        format!(
            "{}, {} about {}, moves body {}",
            j.name,
            kind_name(j.kind),
            vec3(&j.axis, opts.digits),
            id.body_names[i]
        )
    };
    model
        .coordinate_joints()
        .into_iter()
        .enumerate()
        .map(|(c, i)| {
            let mut line = describe(i);
            for (m, k) in model.coupling.iter().enumerate() {
                if k.leader.is_some() && k.coordinate == c {
                    let _ = write!(
                        line,
                        "; mimic joint {} ({} q{} + {})",
                        describe(m),
                        format_number(k.multiplier, opts.digits),
                        c + 1,
                        format_number(k.offset, opts.digits)
                    );
                }
            }
            line
        })
        .collect()
}

/// What is printed, before formatting.
struct Document {
    title: String,
    intro: Vec<String>,
    joints: Vec<String>,
    formulas: Vec<(String, String)>,
    values: Vec<(String, String)>,
    legend: Vec<(String, String)>,
}

impl Document {
    fn text(&self) -> String {
        let mut out = String::new();
        for l in &self.intro {
            let _ = writeln!(out, "{l}");
        }
        let _ = writeln!(out, "Joints:");
        for (i, j) in self.joints.iter().enumerate() {
            let _ = writeln!(out, "  q{}: {j}", i + 1);
        }
        let _ = writeln!(out, "\nBase parameters:");
        for (a, b) in &self.formulas {
            let _ = writeln!(out, "  {a} = {b}");
        }
        let _ = writeln!(out, "\nValues from the URDF:");
        for (a, b) in &self.values {
            let _ = writeln!(out, "  {a} = {b}");
        }
        let _ = writeln!(out, "\nLegend:");
        for (a, b) in &self.legend {
            let _ = writeln!(out, "  {a}: {b}");
        }
        out
    }

    fn latex(&self, standalone: bool) -> String {
        let mut out = String::new();
        if standalone {
            let _ = writeln!(out, "\\documentclass{{article}}");
            let _ = writeln!(out, "\\usepackage{{amsmath}}");
            let _ = writeln!(out, "\\allowdisplaybreaks");
            let _ = writeln!(out, "\\begin{{document}}");
            let _ = writeln!(out, "\\section*{{{}}}", tex_escape(&self.title));
            for l in &self.intro {
                let _ = writeln!(out, "{}\n", tex_escape(l));
            }
            let _ = writeln!(out, "\\begin{{itemize}}");
            for (i, j) in self.joints.iter().enumerate() {
                let _ = writeln!(out, "\\item $q_{{{}}}$: {}", i + 1, tex_escape(j));
            }
            let _ = writeln!(out, "\\end{{itemize}}");
            for (title, lines) in [
                ("Base parameters", &self.formulas),
                ("Values from the URDF", &self.values),
            ] {
                let _ = writeln!(out, "\\section*{{{title}}}");
                align(&mut out, lines);
            }
            let _ = writeln!(out, "\\section*{{Legend}}");
            for (a, b) in &self.legend {
                let _ = writeln!(out, "{}: {}\n", tex_escape(a), tex_escape(b));
            }
            let _ = writeln!(out, "\\end{{document}}");
            return out;
        }
        for l in &self.intro {
            let _ = writeln!(out, "% {l}");
        }
        let _ = writeln!(out, "% Joints:");
        for (i, j) in self.joints.iter().enumerate() {
            let _ = writeln!(out, "%   q{}: {j}", i + 1);
        }
        let _ = writeln!(out, "\n% Base parameters");
        aligned(&mut out, &self.formulas);
        let _ = writeln!(out, "\n% Values from the URDF");
        aligned(&mut out, &self.values);
        let _ = writeln!(out, "\n% Legend");
        for (a, b) in &self.legend {
            let _ = writeln!(out, "% {a}: {b}");
        }
        out
    }

    fn markdown(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "# {}\n", md_escape(&self.title));
        for l in &self.intro {
            let _ = writeln!(out, "{}", md_escape(l));
        }
        let _ = writeln!(out, "\n| coordinate | joint |\n| --- | --- |");
        for (i, j) in self.joints.iter().enumerate() {
            let _ = writeln!(out, "| $q_{{{}}}$ | {} |", i + 1, md_escape(j));
        }
        for (title, lines) in [
            ("Base parameters", &self.formulas),
            ("Values from the URDF", &self.values),
        ] {
            let _ = writeln!(out, "\n## {title}\n\n$$");
            aligned(&mut out, lines);
            let _ = writeln!(out, "$$");
        }
        let _ = writeln!(out, "\n## Legend\n\n| symbol | meaning |\n| --- | --- |");
        for (a, b) in &self.legend {
            let _ = writeln!(out, "| {} | {} |", md_escape(a), md_escape(b));
        }
        out
    }
}
