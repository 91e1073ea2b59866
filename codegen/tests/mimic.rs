//! Mimic joints honoured (`ModelOptions::mimic_joints`, `Builder::mimic_joints`): how the
//! model resolves `<mimic>` tags into couplings, the errors for tags that cannot be honoured,
//! and the combinations the builder refuses. The numbers are checked through compiled code in
//! `tests/tests/mimic.rs`.

use eomgen::model::{Coupling, Model, ModelError, ModelOptions};
use eomgen::urdf::load_str;
use eomgen::Builder;

fn link(name: &str) -> String {
    format!(
        r#"<link name="{name}"><inertial><origin xyz="0.1 0.02 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>"#
    )
}

/// A chain `j1 -> j2 -> j3` of revolute joints (`kind` for `j3`), with extra XML inside each.
fn chain(extra: [&str; 3], kind: &str) -> String {
    let mut text = String::from(r#"<robot name="chain"><link name="base"/>"#);
    for l in ["l1", "l2", "l3"] {
        text += &link(l);
    }
    let parents = ["base", "l1", "l2"];
    let kinds = ["revolute", "revolute", kind];
    for i in 0..3 {
        text += &format!(
            r#"<joint name="j{n}" type="{k}"><parent link="{p}"/><child link="l{n}"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>{x}</joint>"#,
            n = i + 1,
            k = kinds[i],
            p = parents[i],
            x = extra[i]
        );
    }
    text + "</robot>"
}

fn options() -> ModelOptions {
    ModelOptions {
        mimic_joints: true,
        ..ModelOptions::default()
    }
}

fn load(text: &str) -> Result<Model, ModelError> {
    load_str(text, "chain.urdf", &options())
}

#[test]
fn a_mimic_chain_resolves_to_its_root_joint() {
    // j3 = 3 j2 - 0.2, j2 = -0.5 j1 + 0.1: j3 = -1.5 j1 + 0.1.
    let model = load(&chain(
        [
            "",
            r#"<mimic joint="j1" multiplier="-0.5" offset="0.1"/>"#,
            r#"<mimic joint="j2" multiplier="3" offset="-0.2"/>"#,
        ],
        "revolute",
    ))
    .unwrap();
    assert!(model.is_coupled());
    assert_eq!(model.coordinates(), 1);
    assert_eq!(model.coordinate_names(), ["j1"]);
    assert_eq!(model.coupling[0], Coupling::independent(0));
    assert_eq!(
        model.coupling[1],
        Coupling {
            coordinate: 0,
            leader: Some(0),
            multiplier: -0.5,
            offset: 0.1
        }
    );
    let c = model.coupling[2];
    assert_eq!((c.coordinate, c.leader), (0, Some(0)));
    assert!((c.multiplier + 1.5).abs() < 1e-15 && (c.offset - 0.1).abs() < 1e-15);
}

#[test]
fn without_the_option_mimic_joints_stay_coordinates() {
    let text = chain(["", r#"<mimic joint="j1"/>"#, ""], "revolute");
    let model = load_str(&text, "chain.urdf", &ModelOptions::default()).unwrap();
    assert!(!model.is_coupled());
    assert_eq!(model.coordinates(), 3);
    let plain = Builder::from_urdf_str(&text, "chain.urdf")
        .generate()
        .unwrap();
    let honoured = Builder::from_urdf_str(&text, "chain.urdf")
        .mimic_joints()
        .generate()
        .unwrap();
    assert!(plain.contains(r#"const JOINT_NAMES: [&'static str; 3] = ["j1", "j2", "j3"];"#));
    assert!(honoured.contains(r#"const JOINT_NAMES: [&'static str; 2] = ["j1", "j3"];"#));
    assert!(
        honoured.contains("--mimic"),
        "the banner's command says --mimic"
    );
}

#[test]
fn a_prismatic_joint_may_mimic_and_be_mimicked() {
    let model = load(&chain(
        ["", "", r#"<mimic joint="j2" multiplier="0.01"/>"#],
        "prismatic",
    ))
    .unwrap();
    assert_eq!(model.coordinate_names(), ["j1", "j2"]);
    assert_eq!(model.coupling[2].coordinate, 1);
}

fn message(e: ModelError) -> String {
    e.to_string()
}

#[test]
fn a_mimic_of_a_missing_joint_is_an_error_naming_both() {
    let e = load(&chain(["", "", r#"<mimic joint="nowhere"/>"#], "revolute")).unwrap_err();
    assert!(matches!(e, ModelError::InvalidMimic { .. }), "{e:?}");
    assert_eq!(
        message(e),
        "chain.urdf: joint `j3` mimics `nowhere`, which does not exist"
    );
}

#[test]
fn a_mimic_of_a_fixed_joint_is_an_error() {
    let mut text = chain(["", "", r#"<mimic joint="weld"/>"#], "revolute");
    text = text.replace(
        "</robot>",
        &format!(
            r#"{}<joint name="weld" type="fixed"><parent link="l3"/><child link="tool"/></joint></robot>"#,
            link("tool")
        ),
    );
    let e = message(load(&text).unwrap_err());
    assert!(
        e.starts_with("chain.urdf: joint `j3` mimics `weld`, which does not move"),
        "{e}"
    );
}

#[test]
fn a_mimic_tag_on_a_fixed_joint_is_an_error() {
    let e = message(load(&chain(["", "", r#"<mimic joint="j1"/>"#], "fixed")).unwrap_err());
    assert!(
        e.starts_with("chain.urdf: joint `j3` mimics `j1`, but is a fixed joint"),
        "{e}"
    );
}

#[test]
fn a_cycle_of_mimics_is_an_error_listing_it() {
    let e = load(&chain(
        [
            "",
            r#"<mimic joint="j3"/>"#,
            r#"<mimic joint="j2" multiplier="2"/>"#,
        ],
        "revolute",
    ))
    .unwrap_err();
    assert!(matches!(e, ModelError::MimicCycle { .. }), "{e:?}");
    assert_eq!(
        message(e),
        "chain.urdf: the mimic joints `j2` -> `j3` -> `j2` form a cycle: none of them is a coordinate"
    );
    let e = message(load(&chain([r#"<mimic joint="j1"/>"#, "", ""], "revolute")).unwrap_err());
    assert!(e.contains("`j1` -> `j1` form a cycle"), "{e}");
}

#[test]
fn a_floating_base_keeps_its_six_coordinates_before_the_coupled_joints() {
    let text = chain(["", r#"<mimic joint="j1"/>"#, ""], "revolute");
    let source = Builder::from_urdf_str(&text, "chain.urdf")
        .mimic_joints()
        .floating_base()
        .generate()
        .unwrap();
    assert!(source.contains("pub const NQ: usize = 9;"), "7 + 2");
    assert!(source.contains("pub const NV: usize = 8;"), "6 + 2");
    assert!(source.contains(r#"pub const JOINT_NAMES: [&'static str; 2] = ["j1", "j3"];"#));
    // The derivatives take the coupled coordinates too, q perturbed in the tangent space.
    let source = Builder::from_urdf_str(&text, "chain.urdf")
        .mimic_joints()
        .floating_base()
        .derivatives()
        .generate()
        .unwrap();
    assert!(source.contains("pub fn inverse_dynamics_derivatives("));
    assert!(source.contains("-> ([[T; 8]; 8], [[T; 8]; 8], [[T; 8]; 8])"));
}

#[test]
fn mimic_joints_generate_identical_bytes_twice() {
    let text = chain(
        [
            "",
            r#"<mimic joint="j1" multiplier="-0.5" offset="0.1"/>"#,
            "",
        ],
        "prismatic",
    );
    let make = || {
        Builder::from_urdf_str(&text, "chain.urdf")
            .mimic_joints()
            .derivatives()
            .regressor()
            .generate()
            .unwrap()
    };
    assert_eq!(make(), make());
}
