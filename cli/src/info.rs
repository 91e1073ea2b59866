//! `eomgen info`: the kinematic tree, masses, operation counts and timings.

use std::fmt::Write as _;
use std::time::Duration;

use eomgen::model::{JointKind, Model};
use eomgen::report::format_number;
use eomgen::{Derived, Generated, OpCount};

fn kind(k: JointKind) -> &'static str {
    k.urdf_name()
}

fn vec3(v: &nalgebra::Vector3<f64>) -> String {
    let f = |x: f64| format_number(x, Some(6));
    format!("({}, {}, {})", f(v[0]), f(v[1]), f(v[2]))
}

fn ms(d: Duration) -> String {
    format!("{:.1} ms", d.as_secs_f64() * 1e3)
}

/// Joint `j`'s coordinate as `q3`, its position coordinates as `q3..q9` (a floating joint's
/// seven), or `mimic` for a mimic joint that follows another. Counted after a floating base's.
fn label(model: &Model, j: usize) -> String {
    let nq = model.joints[j].kind.nq();
    if nq > 1 || !model.velocities_are_rates() {
        let first = model.q_offsets()[j] - model.base_nq() + 1;
        return match nq {
            1 => format!("q{first}"),
            _ => format!("q{first}..q{}", first + nq - 1),
        };
    }
    match model.coupling.get(j) {
        Some(c) if c.leader.is_some() => "mimic".to_string(),
        Some(c) => format!("q{}", c.coordinate + 1),
        None => format!("q{}", j + 1),
    }
}

/// What `info` says about the URDF's mimic tags: how to honour them, or that they are.
fn mimic_note(model: &Model) -> Option<String> {
    let tagged: Vec<String> = model
        .joints
        .iter()
        .filter(|j| j.mimic.is_some())
        .map(|j| format!("`{}`", j.name))
        .collect();
    if tagged.is_empty() {
        return None;
    }
    Some(if model.is_coupled() {
        format!(
            "mimic joints honoured (--mimic): {} follow(s) the joint(s) they mimic; the {} \
             coordinates are the other joints",
            tagged.join(", "),
            model.coordinates()
        )
    } else {
        format!(
            "the URDF has <mimic> tags on {}: they are independent coordinates here, as in \
             Pinocchio; --mimic (Builder::mimic_joints() in a build script) makes each follow \
             the joint it mimics, with fewer coordinates and the coupling's inertia in M",
            tagged.join(", ")
        )
    })
}

/// One line per generated function: its straight-line operations, or `run time` for one
/// composed at run time from the others (a solve, a loop, a runtime kernel), in catalogue
/// order; functions with both list their straight-line part.
fn operation_counts(derived: &Derived, generated: &Generated) -> String {
    let mut rows: Vec<(&str, Option<&OpCount>)> = derived
        .quantity_names()
        .into_iter()
        .map(|name| {
            let ops = generated.op_counts.iter().find(|(n, _)| n == name);
            (name, ops.map(|(_, o)| o))
        })
        .collect();
    for (name, ops) in &generated.op_counts {
        if !rows.iter().any(|(n, _)| n == name) {
            rows.push((name, Some(ops)));
        }
    }
    let width = rows.iter().map(|(n, _)| n.len()).max().unwrap_or(0);
    let mut out = String::new();
    for (name, ops) in rows {
        let _ = match ops {
            Some(ops) => writeln!(out, "  {name:width$}  {:>7} total: {ops}", ops.total()),
            None => writeln!(out, "  {name:width$}  run time"),
        };
    }
    out
}

/// The report. `load` and `emit` are the times of reading the URDF and of emitting code.
pub fn print(
    derived: &Derived,
    generated: &Generated,
    source: &str,
    load: Duration,
    emit: Duration,
) -> String {
    let model = derived.model();
    let mut out = summary(model, source);
    tree(&mut out, model);
    limits_and_effects(&mut out, model);
    let _ = writeln!(out, "\noperations per call of each generated function:");
    let _ = write!(out, "{}", operation_counts(derived, generated));
    times(&mut out, derived, load, emit);
    out
}

/// The robot, its degrees of freedom, mass and gravity, and the notes on its base and mimic
/// tags.
fn summary(model: &Model, source: &str) -> String {
    let mut out = String::new();
    let total_mass: f64 = model.bodies.iter().chain(&model.base).map(|b| b.mass).sum();
    let _ = writeln!(out, "robot: {} ({source})", model.name);
    if model.is_floating() {
        let _ = writeln!(
            out,
            "degrees of freedom: {} joints + 6 of the floating base (NQ {}, NV {})",
            model.coordinates(),
            model.nq(),
            model.nv()
        );
    } else if model.is_coupled() {
        let _ = writeln!(
            out,
            "degrees of freedom: {} ({} moving joints, {} of them mimic joints following others)",
            model.coordinates(),
            model.dof(),
            model.dof() - model.coordinates()
        );
    } else if !model.velocities_are_rates() {
        let _ = writeln!(
            out,
            "degrees of freedom: {} (floating joints: NQ {}, NV {})",
            model.nv(),
            model.nq(),
            model.nv()
        );
    } else {
        let _ = writeln!(out, "degrees of freedom: {}", model.dof());
    }
    let _ = writeln!(
        out,
        "moving mass: {} kg in {} bodies",
        format_number(total_mass, Some(6)),
        model.bodies.len() + usize::from(model.is_floating())
    );
    let _ = writeln!(out, "gravity: {} m/s^2", vec3(&model.gravity));
    if let Some(note) = super::floating_base::note(model) {
        let _ = writeln!(out, "note: {note}");
    }
    if let Some(note) = mimic_note(model) {
        let _ = writeln!(out, "note: {note}");
    }

    out
}

/// The kinematic tree, depth first with an explicit stack (no recursion on user input).
fn tree(out: &mut String, model: &Model) {
    let _ = writeln!(
        out,
        "\ntree (coordinate, joint: type about its axis in the joint frame -> body, mass):"
    );
    let welded: Vec<&str> = model
        .frames
        .iter()
        .filter(|f| f.body.is_none() && f.name != model.root)
        .map(|f| f.name.as_str())
        .collect();
    let _ = write!(out, "{}", model.root);
    if let Some(base) = &model.base {
        let _ = write!(
            out,
            " (floating base, {} kg)",
            format_number(base.mass, Some(6))
        );
    }
    if !welded.is_empty() {
        let kind = if model.is_floating() {
            "merged"
        } else {
            "welded"
        };
        let _ = write!(out, " ({kind}: {})", welded.join(", "));
    }
    out.push('\n');
    let children = |parent: Option<usize>| -> Vec<usize> {
        (0..model.dof())
            .filter(|&j| model.joints[j].parent == parent)
            .collect()
    };
    // (joint, prefix of its line, whether it is the last child)
    let mut stack: Vec<(usize, String, bool)> = Vec::new();
    let push = |stack: &mut Vec<(usize, String, bool)>, kids: Vec<usize>, prefix: &str| {
        for (k, &j) in kids.iter().enumerate().rev() {
            stack.push((j, prefix.to_string(), k + 1 == kids.len()));
        }
    };
    push(&mut stack, children(None), "");
    while let Some((j, prefix, last)) = stack.pop() {
        tree_line(out, model, j, &prefix, last);
        let deeper = format!("{prefix}{}", if last { "    " } else { "│   " });
        push(&mut stack, children(Some(j)), &deeper);
    }
}

/// Joint `j`'s line of the tree: its coordinate, name, kind, axis (a floating joint has none),
/// body and mass, merged links and mimic tag.
fn tree_line(out: &mut String, model: &Model, j: usize, prefix: &str, last: bool) {
    let joint = &model.joints[j];
    let body = &model.bodies[j];
    // A floating joint moves along no axis.
    let axis = match joint.kind {
        JointKind::Floating => String::new(),
        _ => format!(" about {}", vec3(&joint.axis)),
    };
    let _ = write!(
        out,
        "{prefix}{} {} {}: {}{axis} -> {}, {} kg",
        if last { "└──" } else { "├──" },
        label(model, j),
        joint.name,
        kind(joint.kind),
        body.name,
        format_number(body.mass, Some(6))
    );
    let merged: Vec<&str> = body
        .merged_links
        .iter()
        .skip(1)
        .map(|s| s.as_str())
        .collect();
    if !merged.is_empty() {
        let _ = write!(out, " (merged: {})", merged.join(", "));
    }
    let coupling = model.coupling.get(j).filter(|c| c.leader.is_some());
    match (&joint.mimic, coupling) {
        (Some(m), Some(c)) => {
            let _ = write!(
                out,
                " (mimics {}: follows q{} x {} + {})",
                m.joint,
                c.coordinate + 1,
                format_number(c.multiplier, Some(6)),
                format_number(c.offset, Some(6))
            );
        }
        (Some(m), None) => {
            let _ = write!(
                out,
                " (mimics {} x {} + {}, treated as independent)",
                m.joint,
                format_number(m.multiplier, Some(6)),
                format_number(m.offset, Some(6))
            );
        }
        _ => {}
    }
    out.push('\n');
}

/// The joint limits, and the joint effects when the URDF has any.
fn limits_and_effects(out: &mut String, model: &Model) {
    let _ = writeln!(out, "\njoint limits (lower, upper, effort, velocity):");
    for (i, j) in model.joints.iter().enumerate() {
        let limits = match &j.limits {
            Some(l) => format!(
                "{}, {}, {}, {}",
                format_number(l.lower, Some(6)),
                format_number(l.upper, Some(6)),
                format_number(l.effort, Some(6)),
                format_number(l.velocity, Some(6))
            ),
            None => "none".to_string(),
        };
        let _ = writeln!(out, "  {} {}: {limits}", label(model, i), j.name);
    }

    let has_effects = model
        .joints
        .iter()
        .any(|j| j.damping != 0.0 || j.friction != 0.0 || j.armature != 0.0);
    if has_effects {
        let included = if model.include_friction {
            "friction included in the dynamics"
        } else {
            "friction left out of the dynamics without --friction"
        };
        let _ = writeln!(
            out,
            "\njoint effects (damping, Coulomb friction, rotor inertia; {included}):"
        );
        for (i, j) in model.joints.iter().enumerate() {
            let _ = writeln!(
                out,
                "  {} {}: {}, {}, {}",
                label(model, i),
                j.name,
                format_number(j.damping, Some(6)),
                format_number(j.friction, Some(6)),
                format_number(j.armature, Some(6))
            );
        }
    }
}

/// How long reading, deriving (per stage) and emitting took, and the graph's size.
fn times(out: &mut String, derived: &Derived, load: Duration, emit: Duration) {
    let derive: Duration = derived.timings().iter().map(|t| t.1).sum();
    let stages: Vec<String> = derived
        .timings()
        .iter()
        .map(|(n, t)| format!("{n} {}", ms(*t)))
        .collect();
    let _ = writeln!(out, "\ntimes:");
    let _ = writeln!(out, "  reading the URDF: {}", ms(load));
    let _ = writeln!(
        out,
        "  derivation: {} ({}); expression graph: {} nodes",
        ms(derive),
        stages.join(", "),
        derived.graph_nodes()
    );
    let _ = writeln!(out, "  code generation: {}", ms(emit));
}
