//! Spotting robots that are meant to walk: eomgen welds every root link to the world, which is
//! right for an arm and wrong for a quadruped or a humanoid, whose trunk moves freely.
//!
//! The signs are names: at least two separate chains of joints (not one below another) whose
//! joint or body names speak of legs (`hip`, `thigh`, `knee`, `calf`, `ankle`, `foot`, `leg`,
//! or the `HAA`/`HFE`/`KFE` of ANYmal and Solo).

use eomgen::model::Model;

/// Words that name leg parts, matched in lower case anywhere in a name.
const LEG_WORDS: [&str; 11] = [
    "leg", "hip", "thigh", "knee", "calf", "shank", "ankle", "foot", "haa", "hfe", "kfe",
];

/// The note `info` prints when the robot looks legged, naming the first joint of each leg.
pub fn note(model: &Model) -> Option<String> {
    if model.is_floating() {
        return None;
    }
    let leggy = |i: usize| {
        let names = [&model.joints[i].name, &model.bodies[i].name];
        names.iter().any(|n| {
            let n = n.to_lowercase();
            LEG_WORDS.iter().any(|w| n.contains(w))
        })
    };
    // The first leg joint of each chain: no ancestor is a leg joint.
    let starts: Vec<&str> = (0..model.dof())
        .filter(|&i| leggy(i))
        .filter(|&i| {
            let path = model.path_to_root(i);
            path[..path.len() - 1].iter().all(|&a| !leggy(a))
        })
        .map(|i| model.joints[i].name.as_str())
        .collect();
    if starts.len() < 2 {
        return None;
    }
    let shown: Vec<String> = starts.iter().take(4).map(|s| format!("`{s}`")).collect();
    Some(format!(
        "{} looks like a legged robot ({} legs, from {}{}): eomgen welds its root link `{}` \
         to the world, as for a fixed-base robot; --floating-base (Builder::floating_base) \
         lets it move freely",
        model.name,
        starts.len(),
        shown.join(", "),
        if starts.len() > 4 { ", ..." } else { "" },
        model.root
    ))
}

#[cfg(test)]
mod tests {
    use super::note;

    /// A robot with one chain per `(joint, body)` list, each hanging from the root.
    fn robot(chains: &[&[(&str, &str)]]) -> eomgen::model::Model {
        let link = |name: &str| {
            format!(
                r#"<link name="{name}"><inertial><origin xyz="0.1 0.1 0.1"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"#
            )
        };
        let mut parts = vec![link("trunk")];
        for chain in chains {
            let mut parent = "trunk";
            for (joint, body) in chain.iter() {
                parts.push(link(body));
                parts.push(format!(
                    r#"<joint name="{joint}" type="revolute"><parent link="{parent}"/><child link="{body}"/><limit lower="-1" upper="1" velocity="1"/></joint>"#
                ));
                parent = body;
            }
        }
        let text = format!("<robot name=\"dog\">{}</robot>", parts.concat());
        eomgen::Builder::from_urdf_str(&text, "dog.urdf")
            .model()
            .unwrap()
    }

    #[test]
    fn legs_are_recognized_by_their_names() {
        let leg = |side: &'static str| -> Vec<(String, String)> {
            ["hip", "thigh", "calf"]
                .iter()
                .map(|p| (format!("{side}_{p}_joint"), format!("{side}_{p}")))
                .collect()
        };
        let legs: Vec<Vec<(String, String)>> = ["FL", "FR", "RL", "RR"].map(leg).into();
        let borrowed: Vec<Vec<(&str, &str)>> = legs
            .iter()
            .map(|l| l.iter().map(|(j, b)| (j.as_str(), b.as_str())).collect())
            .collect();
        let chains: Vec<&[(&str, &str)]> = borrowed.iter().map(|c| c.as_slice()).collect();
        let text = note(&robot(&chains)).unwrap();
        assert!(
            text.contains(
                "4 legs, from `FL_hip_joint`, `FR_hip_joint`, `RL_hip_joint`, `RR_hip_joint`"
            ) && text.contains("root link `trunk`"),
            "{text}"
        );
        // One leg is not a legged robot; nor is an arm.
        assert_eq!(note(&robot(&chains[..1])), None);
        assert_eq!(
            note(&robot(&[&[
                ("shoulder", "upper_arm"),
                ("elbow", "forearm")
            ]])),
            None
        );
    }
}
