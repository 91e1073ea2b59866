//! The command line's flags, as ripgrep keeps them: the definitions clap reads (`defs.rs`),
//! how list values are read (`values.rs`), and what the flags mean for the library
//! (`options.rs`). The commands (`commands.rs`) read the parsed structs.

mod defs;
mod options;
mod values;

pub(crate) use defs::*;
pub(crate) use options::cli_error;
pub(crate) use values::Numbers;
