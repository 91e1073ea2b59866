//! eomgen: symbolic equations of motion for robots.
//!
//! eomgen reads a robot's URDF, derives its rigid-body dynamics with its own small computer
//! algebra system ([`cas`]) and emits allocation-free `no_std` Rust that the
//! `eomgen-runtime` crate supports. Most users need only [`Builder`], from a build script:
//!
//! ```no_run
//! // build.rs, with `eomgen` in [build-dependencies] and `eomgen-runtime` in [dependencies]
//! fn main() {
//!     eomgen::Builder::new("robots/panda.urdf").compile().unwrap();
//! }
//! ```
//!
//! and then, in the crate, a robot type with its mass matrix, gravity, Coriolis terms, inverse
//! and forward dynamics, energies, link poses and Jacobians (here the double pendulum that the
//! repository's `generated/` crate holds):
//!
//! ```
//! # mod generated { include!("../../generated/src/double_pendulum.rs"); }
//! # use generated::{DoublePendulum, DoublePendulumLink};
//! // include!(concat!(env!("OUT_DIR"), "/double_pendulum.rs"));
//! use eomgen_runtime::prelude::*;
//!
//! let robot = DoublePendulum::<f64>::default(); // DoublePendulum::<f32> on a microcontroller
//! let (q, qd) = ([0.3, -0.2], [0.0, 0.0]);
//! let hold = robot.inverse_dynamics(&q, &qd, &[0.0, 0.0]); // gravity compensation
//! let g = robot.gravity(&q);
//! assert!((hold[0] - g[0]).abs() < 1e-12 && (hold[1] - g[1]).abs() < 1e-12);
//! let tip: Pose<f64> = robot.link_pose(DoublePendulumLink::Link2, &q);
//! assert!(tip.translation.iter().all(|x| x.is_finite()));
//! ```
//!
//! `.compile().unwrap()` prints a bad URDF's one-line message (`robot.urdf: the robot has no
//! links`): [`Error`]'s `Debug` is its `Display`. The repository's `examples/` crate controls a
//! 7-joint arm generated this way (`cargo run --example computed_torque`), and the `eomgen`
//! command line (crate `eomgen-cli`) prints the same equations for people.
//!
//! Beside [`Builder`], the public API is [`Error`], the [`model`] a builder loads
//! ([`Builder::model`]: its joints, bodies and frames, and [`ModelError`]), the [`catalogue`]
//! of quantities (one name each, symbols as aliases), [`Derived`] and [`evaluate`] (numbers
//! at any state without compiling, [`Builder::derived`]), [`Generated`] (the source and
//! operation counts) and [`report`] (equations for people: text, LaTeX, Markdown; the
//! `eomgen show` command). The `eomgen` command line uses nothing else. The stages in
//! between (URDF reader, computer algebra, kinematics, derivation, emission) are public for
//! the command line and the tests but hidden from this page: they change between minor
//! versions. `docs/architecture.md` in the repository describes them.

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]
// The front page's first example is a whole build.rs.
#![allow(clippy::needless_doctest_main)]

use std::path::{Path, PathBuf};

mod builder;
#[doc(hidden)]
pub mod cas;
pub mod catalogue;
mod debug_display;
#[doc(hidden)]
pub mod dynamics;
#[doc(hidden)]
pub mod emit;
pub mod evaluate;
#[doc(hidden)]
pub mod kinematics;
pub mod model;
mod regenerate;
pub mod report;
#[doc(hidden)]
pub mod spatial;
#[doc(hidden)]
pub mod urdf;
mod wording;

pub use builder::{
    Builder, DEFAULT_MAX_DERIVATIVE_FUNCTION_OPS, DEFAULT_MAX_DOF, DEFAULT_MAX_FUNCTION_OPS,
    DEFAULT_MAX_GRAPH_NODES,
};
pub use cas::OpCount;
pub use dynamics::{Input, Shape};
pub use emit::Generated;
pub use evaluate::Derived;
pub use model::{ModelError, ModelOptions, SymbolicParams};

/// Everything that can go wrong between a URDF and a written module.
///
/// `Debug` prints the same one-line message as `Display`, so that `.compile().unwrap()` in a
/// build script shows it readably:
///
/// ```
/// let err = eomgen::Builder::from_urdf_str("<robot name=\"r\"/>", "empty.urdf")
///     .generate()
///     .unwrap_err();
/// assert_eq!(format!("{err:?}"), err.to_string());
/// assert!(err.to_string().starts_with("empty.urdf: "));
/// ```
#[derive(thiserror::Error)]
pub enum Error {
    /// The URDF is unreadable or describes no valid robot.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Writing the output failed.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// `compile()` outside a build script, without `out_dir`.
    #[error("OUT_DIR is not set: call compile() from a build script, or set Builder::out_dir")]
    NoOutDir,
    /// A user-chosen name that is not a valid identifier of its kind.
    #[error(
        "invalid {what} `{name}`: use an UpperCamelCase type name or a snake_case module name"
    )]
    InvalidName { what: &'static str, name: String },
    /// The robot is beyond a limit of the generator.
    #[error("{file}: {value} {what} exceed the limit of {limit} (raise it with {raise})")]
    Limit {
        file: String,
        what: &'static str,
        value: usize,
        limit: usize,
        raise: &'static str,
    },
    /// [`Builder::quantities`] named something eomgen does not generate.
    /// A combination of options that is not generated (yet).
    #[error("{file}: {what}")]
    Unsupported { file: String, what: &'static str },
    #[error("{file}: unknown quantity `{name}` (known: {known})")]
    UnknownQuantity {
        file: String,
        name: String,
        known: String,
    },
    /// Generated tokens failed to parse: a bug in eomgen.
    #[error("internal error while emitting code (please report): {0}")]
    Emit(String),
}

/// Writes `bytes` to `path` unless the file already holds exactly them, through a temporary file
/// and a rename, so that readers never see a partial file and an unchanged file keeps its
/// modification time (no needless rebuilds).
pub fn write_if_changed(path: &Path, bytes: &[u8]) -> Result<bool, Error> {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return Ok(false);
    }
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    // On any failure (a full disk mid-write, a directory in the way), no temporary file stays.
    std::fs::write(&tmp, bytes)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            io(e)
        })?;
    Ok(true)
}
