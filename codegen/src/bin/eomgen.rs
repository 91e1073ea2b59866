//! The `eomgen` command line: generate code, show equations, describe and evaluate a robot.
//! Run `eomgen --help`.

#[path = "../cli/mod.rs"]
mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
