//! `Builder::quantities`: only the selected functions (and those they call) are generated, the
//! `Dynamics` trait only when all its methods are, and unknown names are errors.

const URDF: &str = r#"<robot name="arm"><link name="base"/>
  <link name="upper"><inertial><origin xyz="0 0 0.2"/><mass value="2"/>
  <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.004"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0 0 0.15"/><mass value="1"/>
  <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
  <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
  <origin xyz="0 0 0.4"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
</robot>"#;

fn generate(names: &[&str]) -> Result<String, eomgen::Error> {
    eomgen::Builder::from_urdf_str(URDF, "arm.urdf")
        .quantities(names.iter().copied())
        .generate()
}

/// The names of the functions the source defines (besides `Default::default` and the batch
/// versions, [`batch_functions`]).
fn functions(source: &str) -> Vec<String> {
    let all = all_functions(source);
    all.into_iter()
        .filter(|f| !f.ends_with("_batch") && f != "in_lanes")
        .collect()
}

/// The `_batch` methods of the source.
fn batch_functions(source: &str) -> Vec<String> {
    let all = all_functions(source);
    all.into_iter().filter(|f| f.ends_with("_batch")).collect()
}

/// The names of every function the source defines (besides `Default::default`).
fn all_functions(source: &str) -> Vec<String> {
    let file = syn::parse_file(source).expect("generated code parses");
    let mut out = Vec::new();
    for item in file.items {
        if let syn::Item::Impl(imp) = item {
            for it in imp.items {
                match it {
                    syn::ImplItem::Fn(f) if f.sig.ident != "default" => {
                        out.push(f.sig.ident.to_string())
                    }
                    _ => {}
                }
            }
        }
    }
    out.sort();
    out
}

#[test]
fn only_the_selected_functions_and_their_helpers_are_generated() {
    let source = generate(&["inverse_dynamics", "gravity"]).unwrap();
    assert_eq!(functions(&source), ["gravity", "inverse_dynamics"]);
    assert_eq!(
        batch_functions(&source),
        ["gravity_batch", "inverse_dynamics_batch"]
    );
    assert!(
        !source.contains("Dynamics<T"),
        "no trait without all its methods"
    );
    assert!(
        source.contains("pub const JOINT_NAMES"),
        "the joint order is still given"
    );

    let source = generate(&["coriolis_pairs"]).unwrap();
    let f = functions(&source);
    assert!(f.contains(&"coriolis_pairs".to_string()), "{f:?}");
    // Flattened for so small an arm, so it needs nothing else.
    assert!(!f.contains(&"mass_matrix".to_string()), "{f:?}");

    let source = generate(&["link_jacobian"]).unwrap();
    assert_eq!(
        functions(&source),
        ["joint_transform", "link_frame", "link_jacobian", "name"]
    );
    // Link kinematics runs on lanes (the runtime's chain kernels are arithmetic), the link the
    // same for every state.
    assert_eq!(batch_functions(&source), ["link_jacobian_batch"]);
    assert!(
        source.contains("link: "),
        "the link is passed once, for every state"
    );
}

#[test]
fn the_trait_is_implemented_when_all_its_methods_are_selected() {
    let all = [
        "mass_matrix",
        "gravity",
        "bias",
        "coriolis_matrix",
        "inverse_dynamics",
        "forward_dynamics",
        "kinetic_energy",
        "potential_energy",
    ];
    let source = generate(&all).unwrap();
    assert!(source.contains("::eomgen_runtime::Dynamics<T, 2> for Arm<T>"));
    assert!(!source.contains("fn link_pose"));
    assert!(!source.contains("fn coriolis_pairs"));
}

#[test]
fn an_unknown_name_is_an_error_listing_the_known_ones() {
    let err = generate(&["inverse_dynamics", "mass_matrx"]).unwrap_err();
    let text = err.to_string();
    assert!(
        text.starts_with("arm.urdf: unknown quantity `mass_matrx`"),
        "{text}"
    );
    assert!(text.contains("mass_matrix, gravity"), "{text}");
}

#[test]
fn every_catalogue_entry_is_consistent_with_its_shape_and_names_are_unique() {
    use eomgen::dynamics::{Derivation, Evaluation};
    let model = eomgen::urdf::load_str(URDF, "arm.urdf", &Default::default()).unwrap();
    let mut d = Derivation::new(&model);
    d.add_derivatives(&model).unwrap();
    let mut names: Vec<&str> = d.quantities.iter().map(|q| q.name).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), d.quantities.len(), "unique names");
    for q in &d.quantities {
        match &q.eval {
            Evaluation::Exprs(ids) => {
                assert_eq!(ids.len(), q.shape.len(), "{}", q.name);
                assert!(q.ops(&d.graph).total() > 0, "{} computes something", q.name);
            }
            Evaluation::ForwardDynamics {
                accelerations,
                pivots,
            } => {
                assert_eq!(accelerations.len(), q.shape.len());
                assert_eq!(pivots.len(), q.shape.len());
            }
            Evaluation::ForwardDynamicsSolve { h } => assert_eq!(h.len(), q.shape.len()),
            Evaluation::Factored { outputs, pivots } => {
                assert_eq!(outputs.len(), q.shape.len(), "{}", q.name);
                assert_eq!(pivots.len(), d.dof, "{}", q.name);
            }
            _ => assert!(q.exprs().is_empty(), "{} is a loop", q.name),
        }
        for needed in q.needs() {
            assert!(d.quantity(needed).is_some(), "{} needs {needed}", q.name);
        }
    }
    assert_eq!(d.quantity("mass_matrix").unwrap().shape.len(), 4);
}
