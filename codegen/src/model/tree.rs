//! The kinematic tree of a description: parents, children and the root checked, joints in
//! depth-first order, and a world link's floating joint turned into the floating base.

use std::collections::HashMap;

use super::description::{JointDescription, JointType, RobotDescription};
use super::errors::ModelError;
use super::JointKind;

/// The validated structure: link indices per joint, the root and the depth-first joint order.
pub(super) struct Tree {
    /// `(parent link, child link)` of each joint, indices into `robot.links`.
    pub(super) ends: Vec<(usize, usize)>,
    pub(super) root: usize,
    /// All joints (fixed ones included), depth first from the root, siblings by name.
    pub(super) order: Vec<usize>,
}

impl Tree {
    pub(super) fn new(robot: &RobotDescription, file: &str) -> Result<Tree, ModelError> {
        if robot.links.is_empty() {
            return Err(ModelError::NoLinks { file: file.into() });
        }
        let link_index = link_index(robot, file)?;
        check_joints(robot, file)?;
        let ends = joint_ends(robot, file, &link_index)?;
        let (parent_joint, mut children) = parent_joints(robot, file, &ends)?;
        let n = robot.links.len();
        let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
        if roots.len() > 1 {
            return Err(ModelError::MultipleRoots {
                file: file.into(),
                roots: roots.iter().map(|&l| robot.links[l].name.clone()).collect(),
            });
        }
        let cycle_error = |start: usize| ModelError::Cycle {
            file: file.into(),
            links: find_cycle(start, &parent_joint, &ends)
                .into_iter()
                .map(|l| robot.links[l].name.clone())
                .collect(),
        };
        let Some(&root) = roots.first() else {
            return Err(cycle_error(0));
        };
        for list in &mut children {
            list.sort_by(|&a, &b| robot.joints[a].name.cmp(&robot.joints[b].name));
        }
        let (order, visited) = depth_first(root, &children, &ends, n);
        if let Some(unreached) = visited.iter().position(|&v| !v) {
            return Err(cycle_error(unreached));
        }
        Ok(Tree { ends, root, order })
    }
}

/// Each link's index by name; a link without a name or with another's name is an error.
fn link_index<'a>(
    robot: &'a RobotDescription,
    file: &str,
) -> Result<HashMap<&'a str, usize>, ModelError> {
    let names = robot.links.iter().map(|l| l.name.as_str());
    unique_names(names, "link", file, |link| ModelError::DuplicateLink {
        file: file.into(),
        link,
    })
}

/// Every joint named, names unique, then every joint of a type eomgen supports.
fn check_joints(robot: &RobotDescription, file: &str) -> Result<(), ModelError> {
    let names = robot.joints.iter().map(|j| j.name.as_str());
    unique_names(names, "joint", file, |joint| ModelError::DuplicateJoint {
        file: file.into(),
        joint,
    })?;
    for joint in &robot.joints {
        if let JointType::Unsupported(kind) = &joint.joint_type {
            return Err(ModelError::UnsupportedJoint {
                file: file.into(),
                joint: joint.name.clone(),
                joint_type: kind.clone(),
            });
        }
    }
    Ok(())
}

/// Each of `names`' index by name; an empty name (of an `element`) is an error, and so is a
/// name given twice (`duplicate` of it).
fn unique_names<'a>(
    names: impl Iterator<Item = &'a str>,
    element: &'static str,
    file: &str,
    duplicate: impl Fn(String) -> ModelError,
) -> Result<HashMap<&'a str, usize>, ModelError> {
    let mut index = HashMap::new();
    for (i, name) in names.enumerate() {
        if name.is_empty() {
            return Err(ModelError::EmptyName {
                file: file.into(),
                element,
                index: i + 1,
            });
        }
        if index.insert(name, i).is_some() {
            return Err(duplicate(name.to_string()));
        }
    }
    Ok(index)
}

/// `(parent link, child link)` of each joint; a link no `<link>` declares is an error.
fn joint_ends(
    robot: &RobotDescription,
    file: &str,
    link_index: &HashMap<&str, usize>,
) -> Result<Vec<(usize, usize)>, ModelError> {
    let lookup = |joint: &JointDescription, link: &str, role| {
        link_index
            .get(link)
            .copied()
            .ok_or_else(|| ModelError::MissingLink {
                file: file.into(),
                joint: joint.name.clone(),
                role,
                link: link.into(),
            })
    };
    robot
        .joints
        .iter()
        .map(|joint| {
            Ok((
                lookup(joint, &joint.parent, "parent")?,
                lookup(joint, &joint.child, "child")?,
            ))
        })
        .collect()
}

/// Each link's parent joint (`None` at a root) and child joints.
type Links = (Vec<Option<usize>>, Vec<Vec<usize>>);

/// The [`Links`] of the tree; a link that is the child of two joints is an error.
fn parent_joints(
    robot: &RobotDescription,
    file: &str,
    ends: &[(usize, usize)],
) -> Result<Links, ModelError> {
    let n = robot.links.len();
    let mut parent_joint: Vec<Option<usize>> = vec![None; n];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (j, &(parent, child)) in ends.iter().enumerate() {
        if let Some(first) = parent_joint[child] {
            return Err(ModelError::MultipleParents {
                file: file.into(),
                link: robot.links[child].name.clone(),
                first: robot.joints[first].name.clone(),
                second: robot.joints[j].name.clone(),
            });
        }
        parent_joint[child] = Some(j);
        children[parent].push(j);
    }
    Ok((parent_joint, children))
}

/// The joints depth first from `root` (children in the order of `children`), and which of the
/// `n` links the walk reached. Iterative: a long chain must not overflow the stack.
fn depth_first(
    root: usize,
    children: &[Vec<usize>],
    ends: &[(usize, usize)],
    n: usize,
) -> (Vec<usize>, Vec<bool>) {
    let mut visited = vec![false; n];
    visited[root] = true;
    let mut order = Vec::with_capacity(ends.len());
    let mut stack: Vec<usize> = children[root].iter().rev().copied().collect();
    while let Some(j) = stack.pop() {
        order.push(j);
        let child = ends[j].1;
        visited[child] = true;
        stack.extend(children[child].iter().rev());
    }
    (order, visited)
}

/// The cycle above `start`, a link unreachable from the root: every link on its chain of
/// parents has a parent, so the chain loops. Returned from parent to child.
pub(super) fn find_cycle(
    start: usize,
    parent_joint: &[Option<usize>],
    ends: &[(usize, usize)],
) -> Vec<usize> {
    let mut chain = Vec::new();
    let mut seen = HashMap::new();
    let mut link = start;
    loop {
        if let Some(&pos) = seen.get(&link) {
            let mut cycle = chain.split_off(pos);
            cycle.reverse();
            return cycle;
        }
        seen.insert(link, chain.len());
        chain.push(link);
        match parent_joint[link] {
            Some(j) => link = ends[j].0,
            // Unreachable for links cut off from the root; report the chain rather than panic.
            None => {
                chain.reverse();
                return chain;
            }
        }
    }
}

/// A robot whose root is a massless link (conventionally `world`) attached to the real root by a
/// single `floating` joint, without that link and joint: the real root then floats. `None`
/// (and `false`) when the robot has no such joint.
pub(super) fn without_world_floating_joint(
    robot: &RobotDescription,
) -> (Option<RobotDescription>, bool) {
    let is_child = |link: &str| robot.joints.iter().any(|j| j.child == link);
    let floating = robot.joints.iter().position(|j| {
        j.joint_type == JointType::Moving(JointKind::Floating)
            && !is_child(&j.parent)
            && robot.joints.iter().filter(|o| o.parent == j.parent).count() == 1
    });
    let Some(f) = floating else {
        return (None, false);
    };
    let world = robot.joints[f].parent.clone();
    let Some(w) = robot.links.iter().position(|l| l.name == world) else {
        return (None, false);
    };
    if robot.links[w].inertial.mass != 0.0 {
        return (None, false);
    }
    let mut out = robot.clone();
    out.joints.remove(f);
    out.links.remove(w);
    (Some(out), true)
}
