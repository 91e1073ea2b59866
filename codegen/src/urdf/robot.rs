//! `<robot>`: its links and joints; what else it holds is ignored, unknown elements with a
//! warning.

use roxmltree::Document;

use super::element::{elements, is, tag};
use super::report::{Context, Report};
use super::{joint, link, markup};
use crate::model::RobotDescription;

/// Top-level elements that other tools read and dynamics does not: ignored silently.
const OTHER_TOOLS: [&str; 5] = ["gazebo", "transmission", "sensor", "ros2_control", "plugin"];

/// The robot in `doc`, with every problem reported to `report`.
pub(super) fn read(doc: &Document, report: &mut Report) -> RobotDescription {
    let top = Context::top();
    let root = doc.root_element();
    let mut robot = RobotDescription {
        name: root.attribute("name").unwrap_or_default().to_string(),
        links: Vec::new(),
        joints: Vec::new(),
    };
    if !is(root, "robot") {
        report.element(
            root,
            &top,
            format!("the root element is {}, not <robot>", tag(root)),
        );
        return robot;
    }
    for child in elements(root) {
        if is(child, "link") {
            robot.links.extend(link::read(child, report));
        } else if is(child, "joint") {
            robot.joints.extend(joint::read(child, report));
        } else if is(child, "material") {
            markup::material(child, &top, report);
        } else if !OTHER_TOOLS.iter().any(|t| is(child, t)) {
            report.warning(
                child,
                &top,
                format!("unknown element {} in <robot> ignored", tag(child)),
            );
        }
    }
    robot
}
