//! The `eomgen` command line (clap): `generate`, `show`, `info`, `eval`, `simulate`. Run
//! `eomgen --help`. It is a crate of its own (`eomgen-cli`) so that build scripts depending on
//! the `eomgen` library compile none of its dependencies.
//!
//! Exit codes: 0 on success, 1 on bad input (one line on stderr, starting with
//! `eomgen: error:`), 2 on bad usage (clap's message). Nothing panics visibly: a panic would be
//! a bug, and is reported as one line too.

mod commands;
mod conditioning;
mod eval;
mod flags;
mod floating_base;
mod info;
mod plot;
mod progress;
mod simulate;
mod simulate_floating;
mod symplectic;

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use clap::Parser;

use eomgen::model::Model;
use eomgen::{Builder, Derived};

use flags::{cli_error, Cli, Command};

/// A failure to report on stderr with exit status 1.
struct Failure(String);

impl<E: std::fmt::Display> From<E> for Failure {
    fn from(e: E) -> Failure {
        Failure(e.to_string())
    }
}

/// Entry point of the binary.
fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
        }
    };
    // A panic is a bug: report it in one line, without a backtrace.
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(|| run(cli)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Failure(format!("internal error: {what} (please report)")))
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(message)) => {
            // One line per line of the message (a file's format errors come one per line),
            // and no control or bidirectional-text characters from names in the URDF reach
            // the terminal.
            for line in message.lines().filter(|l| !l.trim().is_empty()) {
                let line = line.split_whitespace().collect::<Vec<_>>().join(" ");
                let line = terminal_safe(&line);
                let _ = writeln!(std::io::stderr(), "eomgen: error: {line}");
            }
            ExitCode::from(1)
        }
    }
}

/// Writes to stdout; a closed pipe (`eomgen show ... | head`) is not an error.
/// Control characters other than newline and tab, and bidirectional-text controls, from names
/// in a URDF must not drive the terminal: each is written as an escape such as `\u{1b}`.
fn terminal_safe(text: &str) -> String {
    text.split('\n')
        .map(eomgen::report::escape_controls)
        .collect::<Vec<_>>()
        .join("\n")
}

fn emit(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    let text = terminal_safe(text);
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Failure(format!("cannot write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// The file name of a path, for headings (never a full path of this machine).
fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

/// Loads the model of `b`, printing its warnings on stderr whether loading succeeds or not.
fn load(b: &Builder) -> Result<Model, Failure> {
    let (model, warnings) = b.model_with_warnings();
    warn(&warnings);
    Ok(model?)
}

/// Prints the model's warnings on stderr, one line each.
fn warn(warnings: &[eomgen::model::ModelWarning]) {
    warn_lines(warnings.iter().map(|w| w.to_string()));
}

/// Prints warnings on stderr, one line each.
fn warn_lines(warnings: impl IntoIterator<Item = String>) {
    for w in warnings {
        let line = w.split_whitespace().collect::<Vec<_>>().join(" ");
        let line = terminal_safe(&line);
        let _ = writeln!(std::io::stderr(), "eomgen: warning: {line}");
    }
}

/// Derives within the limits of `b` (degrees of freedom, graph size), for the evaluator
/// (`eval`, `simulate`) and the reports (`show`).
fn derived(b: &Builder, model: Model) -> Result<Derived, Failure> {
    let label = format!(
        "deriving the equations of {} ({} joints)",
        model.name,
        model.dof()
    );
    progress::run(&label, || b.derived_from(model)).map_err(cli_error)
}

fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Generate(a) => commands::generate(a),
        Command::Show(a) => commands::show(a),
        Command::Info(a) => commands::info_cmd(a),
        Command::Eval(a) => commands::eval_cmd(a),
        Command::Simulate(a) => commands::simulate_cmd(a),
    }
}
