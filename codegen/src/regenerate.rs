//! The banner's "Regenerate:" line: the `eomgen generate` command that writes the same file,
//! with the options the [`Builder`](crate::Builder) was given, quoted for a POSIX shell so that
//! it works when pasted (from the directory the URDF path is relative to: the crate root for a
//! build script).

use std::fmt::Write as _;
use std::path::Path;

use crate::model::{ModelOptions, SymbolicParams};

/// What the command needs besides the model options.
pub(crate) struct Command<'a> {
    pub urdf: &'a Path,
    pub type_name: &'a str,
    /// The module name, and whether the builder was given it (else it is the default).
    pub module_name: &'a str,
    pub module_name_given: bool,
    pub max_dof: usize,
    pub max_graph_nodes: usize,
    /// `Builder::quantities`, when given.
    pub quantities: Option<&'a [String]>,
    /// `Builder::derivatives`.
    pub derivatives: bool,
    /// `Builder::regressor`.
    pub regressor: bool,
}

/// `eomgen generate URDF --type-name T [options] -o MODULE.rs  # ...`.
pub(crate) fn command_line(c: &Command, o: &ModelOptions) -> String {
    let mut line = format!(
        "eomgen generate {} --type-name {}",
        quote(&urdf_argument(c.urdf)),
        quote(c.type_name)
    );
    if c.module_name_given {
        let _ = write!(line, " --module-name {}", quote(c.module_name));
    }
    for (flag, value) in flags(o) {
        let _ = write!(line, " --{flag}");
        if let Some(v) = value {
            let _ = write!(line, " {}", quote(&v));
        }
    }
    if c.max_dof != crate::DEFAULT_MAX_DOF {
        let _ = write!(line, " --max-dof {}", c.max_dof);
    }
    if c.max_graph_nodes != crate::DEFAULT_MAX_GRAPH_NODES {
        let _ = write!(line, " --max-graph-nodes {}", c.max_graph_nodes);
    }
    if c.derivatives {
        line.push_str(" --derivatives");
    }
    if c.regressor {
        line.push_str(" --regressor");
    }
    if let Some(names) = c.quantities {
        let _ = write!(line, " --only {}", quote(&names.join(",")));
    }
    let module = quote(&format!("{}.rs", c.module_name));
    let _ = write!(line, " -o {module}  # or eomgen::Builder in build.rs");
    line
}

/// The URDF as given when relative; only its file name when absolute, so that no path of the
/// machine that generated the file is written into it.
fn urdf_argument(urdf: &Path) -> String {
    let shown = match urdf.is_absolute() {
        true => urdf.file_name().map(Path::new).unwrap_or(urdf),
        false => urdf,
    };
    shown.to_string_lossy().into_owned()
}

/// The command-line flags for the options that differ from the defaults.
fn flags(o: &ModelOptions) -> Vec<(&'static str, Option<String>)> {
    let d = ModelOptions::default();
    let numbers = |v: &[f64]| v.iter().map(f64::to_string).collect::<Vec<_>>().join(",");
    let mut f = Vec::new();
    if o.gravity != d.gravity {
        f.push(("gravity", Some(numbers(&o.gravity))));
    }
    if let Some(order) = &o.joint_order {
        f.push(("joint-order", Some(order.join(","))));
    }
    match &o.symbolic {
        SymbolicParams::None => {}
        SymbolicParams::All => f.push(("symbolic", None)),
        SymbolicParams::Links(links) => f.push(("symbolic", Some(links.join(",")))),
    }
    // Zero rotor inertia changes nothing in the output: left out, as the default.
    let pairs: Vec<String> = (o.armature.iter().filter(|(_, v)| *v != 0.0))
        .map(|(j, v)| format!("{j}={v}"))
        .collect();
    if !pairs.is_empty() {
        f.push(("armature", Some(pairs.join(","))));
    }
    if o.friction {
        f.push(("friction", None));
    }
    if o.coulomb_smoothing != d.coulomb_smoothing {
        f.push(("coulomb-smoothing", Some(o.coulomb_smoothing.to_string())));
    }
    if let Some(density) = o.inertia_from_collision {
        f.push(("density", Some(density.to_string())));
    }
    if o.repair_inertia {
        f.push(("repair-inertia", None));
    }
    if o.floating_base {
        f.push(("floating-base", None));
    }
    for link in &o.contact_points {
        f.push(("contact", Some(link.clone())));
    }
    for (link, p) in &o.contact_points_at {
        let at = format!("{link}:{},{},{}", p[0], p[1], p[2]);
        f.push(("contact-at", Some(at)));
    }
    for link in &o.contact_frames {
        f.push(("contact-frame", Some(link.clone())));
    }
    for joint in &o.passive_joints {
        f.push(("passive", Some(joint.clone())));
    }
    if o.mimic_joints {
        f.push(("mimic", None));
    }
    f
}

/// `arg` for a POSIX shell: as is when it holds only safe characters, else in single quotes.
fn quote(arg: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-./,=:+".contains(c);
    if !arg.is_empty() && arg.chars().all(safe) {
        return arg.to_string();
    }
    format!("'{}'", arg.replace('\'', r"'\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(urdf: &str) -> Command<'_> {
        Command {
            urdf: Path::new(urdf),
            type_name: "Panda",
            module_name: "panda",
            module_name_given: false,
            max_dof: crate::DEFAULT_MAX_DOF,
            max_graph_nodes: crate::DEFAULT_MAX_GRAPH_NODES,
            quantities: None,
            derivatives: false,
            regressor: false,
        }
    }

    #[test]
    fn defaults_give_the_short_command() {
        let line = command_line(&command("robots/panda.urdf"), &ModelOptions::default());
        assert_eq!(
            line,
            "eomgen generate robots/panda.urdf --type-name Panda -o panda.rs  \
             # or eomgen::Builder in build.rs"
        );
    }

    #[test]
    fn options_become_flags_and_odd_arguments_are_quoted() {
        let o = ModelOptions {
            gravity: [0.0, -9.81, 0.0],
            symbolic: SymbolicParams::Links(vec!["link 2".into()]),
            armature: vec![("j1".into(), 0.1)],
            friction: true,
            inertia_from_collision: Some(1000.0),
            ..ModelOptions::default()
        };
        let mut c = command("/home/someone/my robot's.urdf");
        c.max_dof = 50;
        c.module_name_given = true;
        let line = command_line(&c, &o);
        assert_eq!(
            line,
            "eomgen generate 'my robot'\\''s.urdf' --type-name Panda --module-name panda \
             --gravity 0,-9.81,0 \
             --symbolic 'link 2' --armature j1=0.1 --friction --density 1000 --max-dof 50 \
             -o panda.rs  # or eomgen::Builder in build.rs"
        );
    }

    #[test]
    fn quoting_is_inert_for_the_shell() {
        assert_eq!(quote("a b"), "'a b'");
        assert_eq!(quote("$(rm -rf x)"), "'$(rm -rf x)'");
        assert_eq!(quote("it's"), r"'it'\''s'");
        assert_eq!(quote(""), "''");
    }
}
