//! Workspace-level test support: the Pinocchio reference values of `tests/robots/*.json` and
//! a tolerance checker that reports every mismatch at once.
//!
//! The reference robots and their JSON come from the shared reference set (see
//! `tests/robots/README.md`): twelve states per robot, computed by Pinocchio 4.1.

#![allow(clippy::needless_range_loop)]

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde_json::Value;

/// The five reference robots.
pub const ROBOTS: [&str; 5] = [
    "double_pendulum",
    "ur5",
    "panda",
    "kinova",
    "allegro_right_hand",
];

/// Path of a reference robot's URDF.
pub fn urdf_path(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("robots")
        .join(format!("{robot}.urdf"))
}

/// One link frame of a sample.
#[derive(Clone, Debug)]
pub struct FrameRef {
    pub position: Vec<f64>,
    pub rotation: Vec<Vec<f64>>,
    /// 6 x N, columns in the reference's joint order.
    pub jacobian: Vec<Vec<f64>>,
}

/// One reference state and everything Pinocchio computed there.
#[derive(Clone, Debug)]
pub struct Sample {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
    pub mass_matrix: Vec<Vec<f64>>,
    pub gravity: Vec<f64>,
    pub bias: Vec<f64>,
    pub coriolis_matrix: Vec<Vec<f64>>,
    pub tau_in: Vec<f64>,
    pub forward_dynamics: Vec<f64>,
    pub kinetic_energy: f64,
    pub potential_energy: f64,
    pub frames: BTreeMap<String, FrameRef>,
    pub centrifugal: Option<Vec<Vec<f64>>>,
    pub coriolis_pairs: Option<Vec<Vec<f64>>>,
}

/// A robot's reference file.
#[derive(Clone, Debug)]
pub struct Reference {
    pub robot: String,
    /// Moving joints in the reference's order.
    pub joints: Vec<String>,
    pub samples: Vec<Sample>,
}

fn vec1(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn vec2(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("array").iter().map(vec1).collect()
}

/// Loads `tests/robots/<robot>.json`.
pub fn load(robot: &str) -> Reference {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("robots")
        .join(format!("{robot}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let v: Value = serde_json::from_str(&text).expect("valid JSON");
    let joints = v["joints"]
        .as_array()
        .expect("joints")
        .iter()
        .map(|j| j.as_str().unwrap().to_string())
        .collect();
    let samples = v["samples"]
        .as_array()
        .expect("samples")
        .iter()
        .map(|s| Sample {
            q: vec1(&s["q"]),
            qd: vec1(&s["qd"]),
            qdd: vec1(&s["qdd"]),
            tau: vec1(&s["tau"]),
            mass_matrix: vec2(&s["mass_matrix"]),
            gravity: vec1(&s["gravity"]),
            bias: vec1(&s["bias"]),
            coriolis_matrix: vec2(&s["coriolis_matrix"]),
            tau_in: vec1(&s["tau_in"]),
            forward_dynamics: vec1(&s["forward_dynamics"]),
            kinetic_energy: s["kinetic_energy"].as_f64().unwrap(),
            potential_energy: s["potential_energy"].as_f64().unwrap(),
            frames: s["frames"]
                .as_object()
                .expect("frames")
                .iter()
                .map(|(k, f)| {
                    let fr = FrameRef {
                        position: vec1(&f["position"]),
                        rotation: vec2(&f["rotation"]),
                        jacobian: vec2(&f["jacobian"]),
                    };
                    (k.clone(), fr)
                })
                .collect(),
            centrifugal: s.get("centrifugal").map(vec2),
            coriolis_pairs: s.get("coriolis_pairs").map(vec2),
        })
        .collect();
    Reference {
        robot: robot.to_string(),
        joints,
        samples,
    }
}

/// Maps the reference's joint order onto another order of the same names.
#[derive(Clone, Debug)]
pub struct JointMap {
    /// `ours[k]`: our index of the reference's joint `k`.
    pub ours: Vec<usize>,
}

impl JointMap {
    /// Builds the map; panics when the names differ as sets.
    pub fn new(reference: &[String], ours: &[&str]) -> JointMap {
        assert_eq!(reference.len(), ours.len(), "degrees of freedom");
        let map = reference
            .iter()
            .map(|name| {
                ours.iter()
                    .position(|o| o == name)
                    .unwrap_or_else(|| panic!("joint {name} missing"))
            })
            .collect();
        JointMap { ours: map }
    }
    /// A reference-ordered vector in our order.
    pub fn to_ours(&self, v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        for (k, &i) in self.ours.iter().enumerate() {
            out[i] = v[k];
        }
        out
    }
    /// Our pair index of the reference's pair `(a, b)`, `a < b`.
    pub fn pair(&self, a: usize, b: usize) -> usize {
        let n = self.ours.len();
        let (j, k) = (
            self.ours[a].min(self.ours[b]),
            self.ours[a].max(self.ours[b]),
        );
        // Pairs (0,1), (0,2), ..., (0,n-1), (1,2), ...
        j * n - j * (j + 1) / 2 + (k - j - 1)
    }
}

/// Collects mismatches beyond `|a - b| <= tol * max(1, |b|)` and reports them all.
#[derive(Debug)]
pub struct Checker {
    pub tol: f64,
    pub compared: usize,
    pub failures: Vec<String>,
}

impl Checker {
    pub fn new(tol: f64) -> Checker {
        Checker {
            tol,
            compared: 0,
            failures: Vec::new(),
        }
    }
    /// Compares one number.
    pub fn check(&mut self, what: impl FnOnce() -> String, got: f64, want: f64) {
        self.compared += 1;
        let ok = (got - want).abs() <= self.tol * want.abs().max(1.0);
        if !ok && self.failures.len() < 40 {
            self.failures
                .push(format!("{}: got {got:e}, want {want:e}", what()));
        }
    }
    /// Panics with every failure when there was one.
    pub fn finish(self, context: &str) {
        assert!(self.compared > 0, "{context}: nothing compared");
        assert!(
            self.failures.is_empty(),
            "{context}: {} mismatches (first {}):\n{}",
            self.failures.len(),
            self.failures.len(),
            self.failures.join("\n")
        );
    }
}

/// A small deterministic generator of test inputs (64-bit LCG).
pub struct Lcg(pub u64);

impl Lcg {
    /// The next number, uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

pub mod floating_reference;

/// The robots the tests call: generated by this crate's build script through `eomgen::Builder`,
/// as a user's build script would, except the reference robots themselves (re-exported).
pub mod robots {
    /// The reference robots (and the iris drone, on a floating base) as generated once, in
    /// `eomgen-generated`, whose golden test checks them against what eomgen generates now.
    pub use eomgen_generated::{
        allegro_right_hand, double_pendulum, iris_simple, kinova, panda, ur5,
    };

    /// `fixtures/acrobot.urdf` with its elbow passive.
    pub mod acrobot {
        include!(concat!(env!("OUT_DIR"), "/acrobot.rs"));
    }

    /// `ur5.urdf` with two passive wrist joints.
    pub mod ur5_passive_wrist {
        include!(concat!(env!("OUT_DIR"), "/ur5_passive_wrist.rs"));
    }

    /// anymal on its four feet: contact and impulse dynamics with their derivatives, and the
    /// MPC kit's kinematics (link motion, the configuration manifold, the centroidal momentum
    /// rate).
    pub mod anymal_mpc {
        include!(concat!(env!("OUT_DIR"), "/anymal_mpc.rs"));
    }
    /// anymal on two feet (`LF_FOOT`, `RH_FOOT`): what `anymal_mpc`'s `_active` methods give
    /// with the other two switched off.
    pub mod anymal_two_feet {
        include!(concat!(env!("OUT_DIR"), "/anymal_two_feet.rs"));
    }
    /// anymal on its four feet with contact and impulse dynamics solved at run time (the
    /// route of robots over the straight-line budget).
    pub mod anymal_solved {
        include!(concat!(env!("OUT_DIR"), "/anymal_solved.rs"));
    }
    /// anymal with contact points at positions in its feet's frames.
    pub mod anymal_at {
        include!(concat!(env!("OUT_DIR"), "/anymal_at.rs"));
    }
    /// g1_29dof with 6D contacts at both soles: contact and impulse dynamics with their
    /// derivatives; opt-in, with `EOMGEN_TEST_HEAVY=1`.
    #[cfg(heavy)]
    pub mod g1_mpc {
        include!(concat!(env!("OUT_DIR"), "/g1_mpc.rs"));
    }

    /// `fixtures/joint_effects.urdf`, rigid body only (upper arm filled at 1000 kg/m^3).
    pub mod joint_effects {
        include!(concat!(env!("OUT_DIR"), "/joint_effects.rs"));
    }
    /// The same with joint friction and rotor inertia (shoulder 0.2, elbow 0.05 kg m^2).
    pub mod joint_effects_full {
        include!(concat!(env!("OUT_DIR"), "/joint_effects_full.rs"));
    }
    /// The same with Coulomb friction smoothed below 0.05 rad/s.
    pub mod joint_effects_smooth {
        include!(concat!(env!("OUT_DIR"), "/joint_effects_smooth.rs"));
    }
    /// `panda.urdf` with its mimic joint honoured (8 coordinates) and the derivatives.
    pub mod panda_mimic {
        include!(concat!(env!("OUT_DIR"), "/panda_mimic.rs"));
    }
    /// `fixtures/mimic_tree.urdf` with its mimic joints honoured (4 coordinates), joint
    /// friction, rotor inertia and the derivatives.
    pub mod mimic_tree {
        include!(concat!(env!("OUT_DIR"), "/mimic_tree.rs"));
    }
    /// The same tree without the option: every joint a coordinate (8).
    pub mod mimic_tree_full {
        include!(concat!(env!("OUT_DIR"), "/mimic_tree_full.rs"));
    }
    /// The mimic tree on a floating base (its root link free), with contacts at `tip` and
    /// `lb2`, mimic joints honoured (6 + 4 velocity coordinates).
    pub mod mimic_tree_floating {
        include!(concat!(env!("OUT_DIR"), "/mimic_tree_floating.rs"));
    }
    /// The same without the option (6 + 8).
    pub mod mimic_tree_floating_full {
        include!(concat!(env!("OUT_DIR"), "/mimic_tree_floating_full.rs"));
    }
    /// `urdf/light_tip.urdf`: a 1e-12 kg last link, an ill-conditioned mass matrix.
    pub mod light_tip {
        include!(concat!(env!("OUT_DIR"), "/light_tip.rs"));
    }
    /// `panda.urdf` with only `inverse_dynamics`, `gravity` and `coriolis_pairs` selected
    /// (`Builder::quantities`): no `Dynamics` implementation, inherent methods only.
    pub mod panda_selected {
        include!(concat!(env!("OUT_DIR"), "/panda_selected.rs"));
    }
    /// `panda.urdf` with the MPC kit's kinematics (link velocities, accelerations, Jacobian
    /// time variations, the configuration manifold) and `link_jacobian`.
    pub mod panda_mpc {
        include!(concat!(env!("OUT_DIR"), "/panda_mpc.rs"));
    }
    /// A synthetic 28-joint serial chain with only forward and inverse dynamics: forward
    /// dynamics solves at run time (the tree `L^T D L` factorization, unrolled).
    pub mod chain28 {
        include!(concat!(env!("OUT_DIR"), "/chain28.rs"));
    }
    /// The reference robots with `Builder::derivatives`, inverse dynamics, its derivatives,
    /// forward-dynamics derivatives and `M^-1` (and what those call) only.
    pub mod ur5_derivatives {
        include!(concat!(env!("OUT_DIR"), "/ur5_derivatives.rs"));
    }
    /// See [`ur5_derivatives`].
    pub mod panda_derivatives {
        include!(concat!(env!("OUT_DIR"), "/panda_derivatives.rs"));
    }
    /// See [`ur5_derivatives`].
    pub mod kinova_derivatives {
        include!(concat!(env!("OUT_DIR"), "/kinova_derivatives.rs"));
    }
    /// See [`ur5_derivatives`].
    pub mod allegro_derivatives {
        include!(concat!(env!("OUT_DIR"), "/allegro_derivatives.rs"));
    }
    /// `ur5.urdf`'s derivatives split into blocks of at most 60 operations.
    pub mod ur5_split {
        include!(concat!(env!("OUT_DIR"), "/ur5_split.rs"));
    }
    /// `anymal` below with every body split into blocks of at most 150 operations.
    pub mod anymal_split {
        include!(concat!(env!("OUT_DIR"), "/anymal_split.rs"));
    }
    /// `floating/anymal.urdf` with a floating base and point contacts at its four feet.
    pub mod anymal {
        include!(concat!(env!("OUT_DIR"), "/anymal.rs"));
    }
    /// `floating/anymal.urdf` without gravity: forward dynamics, the centroidal map, the
    /// kinetic energy and `integrate` only.
    pub mod anymal_weightless {
        include!(concat!(env!("OUT_DIR"), "/anymal_weightless.rs"));
    }
    /// `floating/anymal.urdf` with a floating base and the derivatives of its dynamics (and
    /// what they are checked with).
    pub mod anymal_derivatives {
        include!(concat!(env!("OUT_DIR"), "/anymal_derivatives.rs"));
    }
    /// anymal with `M^-1` and the forward-dynamics derivatives through the tree at run time
    /// (the route of large robots), for `tests/tree_route.rs`.
    pub mod anymal_tree_route {
        include!(concat!(env!("OUT_DIR"), "/anymal_tree_route.rs"));
    }
    /// `double_pendulum.urdf` with identification (`Builder::regressor`) and inverse dynamics.
    pub mod double_pendulum_regressor {
        include!(concat!(env!("OUT_DIR"), "/double_pendulum_regressor.rs"));
    }
    /// `ur5.urdf` with identification and inverse dynamics.
    pub mod ur5_regressor {
        include!(concat!(env!("OUT_DIR"), "/ur5_regressor.rs"));
    }
    /// `panda.urdf` with identification and inverse dynamics.
    pub mod panda_regressor {
        include!(concat!(env!("OUT_DIR"), "/panda_regressor.rs"));
    }
    /// `kinova.urdf` with identification and inverse dynamics.
    pub mod kinova_regressor {
        include!(concat!(env!("OUT_DIR"), "/kinova_regressor.rs"));
    }
    /// `allegro_right_hand.urdf` with identification and inverse dynamics.
    pub mod allegro_regressor {
        include!(concat!(env!("OUT_DIR"), "/allegro_regressor.rs"));
    }
    /// The joint-effects arm with rotor inertia, friction and identification.
    pub mod joint_effects_regressor {
        include!(concat!(env!("OUT_DIR"), "/joint_effects_regressor.rs"));
    }

    /// `xarm7.urdf` (a 7-joint arm that is not one of the five reference robots) likewise;
    /// opt-in, with `EOMGEN_TEST_UNSHIPPED=1`.
    #[cfg(unshipped)]
    pub mod xarm7_derivatives {
        include!(concat!(env!("OUT_DIR"), "/xarm7_derivatives.rs"));
    }
    /// `fixtures/joint_effects.urdf` with friction (Coulomb smoothed below 0.05 rad/s), rotor
    /// inertia and the derivatives.
    pub mod joint_effects_derivatives {
        include!(concat!(env!("OUT_DIR"), "/joint_effects_derivatives.rs"));
    }
    /// `codegen/tests/urdf/hostile/names.urdf`: link and joint names that try to break out of
    /// comments and string literals; compiling this module is the test.
    pub mod hostile_names {
        include!(concat!(env!("OUT_DIR"), "/hostile_names.rs"));
    }
}

/// A global allocator that counts this thread's allocations, to prove code allocation-free.
///
/// A test binary installs it with
/// `#[global_allocator] static GLOBAL: Counting = Counting;` and measures with
/// [`alloc_counter::allocations`].
pub mod alloc_counter {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    /// Forwards to the system allocator and counts, on threads that are measuring.
    pub struct Counting;

    thread_local! {
        // Only this thread's allocations count, in this thread's counter: the test harness
        // allocates on its own threads, and tests counting on two threads at once must not see
        // each other's allocations.
        static COUNTING: Cell<bool> = const { Cell::new(false) };
        static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    }

    // SAFETY: forwards every call unchanged to the system allocator; only counts.
    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            if COUNTING.with(Cell::get) {
                ALLOCATIONS.with(|n| n.set(n.get() + 1));
            }
            unsafe { System.alloc(layout) }
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            unsafe { System.dealloc(ptr, layout) }
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            if COUNTING.with(Cell::get) {
                ALLOCATIONS.with(|n| n.set(n.get() + 1));
            }
            unsafe { System.realloc(ptr, layout, new_size) }
        }
    }
    /// Allocations made by `f` on this thread (needs [`Counting`] as the global allocator).
    pub fn allocations(f: impl FnOnce()) -> usize {
        let before = ALLOCATIONS.with(Cell::get);
        COUNTING.with(|c| c.set(true));
        f();
        COUNTING.with(|c| c.set(false));
        ALLOCATIONS.with(Cell::get) - before
    }
}
