//! How generation time and the operation counts of each generated function grow with the number
//! of joints, on a synthetic serial chain (see `tests/support/chain.rs`).
//!
//!     cargo run --release -p eomgen --example scaling -- [--min 2] [--max 24] [--step 1] \
//!         [--out docs/scaling.md] [--keep DIR]
//!
//! `--keep DIR` writes the chains' URDFs to DIR and leaves them there (for `scripts/build-cost`).
//!
//! Prints a Markdown document (to `--out`, or to stdout); progress goes to stderr.

use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[path = "../tests/support/chain.rs"]
mod chain;

/// In the output file, this line and what follows it are kept when the file is rewritten.
const KEEP_MARKER: &str = "<!-- kept by the scaling example: measured by scripts/build-cost -->";

/// What one chain length measured.
struct Row {
    n: usize,
    total: Duration,
    /// Derivation stages, as `Derivation::timings` names them.
    stages: Vec<(&'static str, Duration)>,
    source_bytes: usize,
    /// (function, [mul, add, div, sin, cos, sqrt]).
    ops: Vec<(String, [usize; 6])>,
}

fn measure(dir: &std::path::Path, n: usize) -> Result<Row, String> {
    let path = chain::write_serial_chain(dir, n).map_err(|e| e.to_string())?;
    let start = Instant::now();
    let (generated, _model, derivation) = eomgen::Builder::new(&path)
        .generate_with_report()
        .map_err(|e| e.to_string())?;
    let total = start.elapsed();
    let ops = generated
        .op_counts
        .iter()
        .map(|(name, o)| (name.clone(), [o.mul, o.add, o.div, o.sin, o.cos, o.sqrt]))
        .collect();
    Ok(Row {
        n,
        total,
        stages: derivation.timings.clone(),
        source_bytes: generated.source.len(),
        ops,
    })
}

/// Growth exponent p in ops ~ n^p between the two largest chains measured (where both counts are
/// non-zero): 1 is linear, 2 quadratic.
fn exponent(rows: &[Row], f: &str, k: usize) -> Option<f64> {
    let pts: Vec<(usize, usize)> = rows
        .iter()
        .filter_map(|r| r.ops.iter().find(|(g, _)| g == f).map(|(_, o)| (r.n, o[k])))
        .filter(|&(_, v)| v > 0)
        .collect();
    let &last = pts.last()?;
    // The chain about half as long, for a slope over a wide span.
    let &first = pts
        .iter()
        .rev()
        .find(|p| p.0 <= last.0 / 2)
        .or(pts.first())?;
    (first.0 < last.0)
        .then(|| (last.1 as f64 / first.1 as f64).ln() / (last.0 as f64 / first.0 as f64).ln())
}

fn secs(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64())
}

fn render(rows: &[Row], functions: &[String], stages: &[&'static str]) -> String {
    let mut s = String::new();
    let cmd = "cargo run --release -p eomgen --example scaling -- --min 4 --max 64 --step 4 \
               --out docs/scaling.md";
    let _ = writeln!(s, "# Scaling with the number of joints\n");
    let _ = writeln!(
        s,
        "Produced by `{cmd}` (`codegen/examples/scaling.rs`): for each n it writes a synthetic \
         serial chain of n revolute joints (`codegen/tests/support/chain.rs`: axes alternating \
         z and y, joint origins offset along all three axes, centres of mass off the axes, full \
         inertia tensors), runs `eomgen::Builder::generate_with_report` once and records its \
         wall-clock time and the operation count of every straight-line generated function (a \
         blank cell: that function is a loop over a runtime kernel, as Craig's forms are beyond \
         16 joints or 8,000 operations; link poses and Jacobians always are). Times are from one run on a shared \
         2-core machine: read them for growth, not to a few percent.\n"
    );
    render_times(&mut s, rows, stages);
    render_ops(&mut s, rows, functions);
    render_rare_ops(&mut s, rows, functions);
    s
}

/// The table of generation times: the total, each stage of the derivation, the rest.
fn render_times(s: &mut String, rows: &[Row], stages: &[&'static str]) {
    let _ = writeln!(s, "## Generation time (seconds)\n");
    let _ = write!(s, "| n | total |");
    for st in stages {
        let _ = write!(s, " {st} |");
    }
    let _ = writeln!(s, " rest (URDF, emit, format) | source (KiB) |");
    let _ = writeln!(s, "|{}", "---:|".repeat(stages.len() + 4));
    for r in rows {
        let _ = write!(s, "| {} | {} |", r.n, secs(r.total));
        let mut derived = Duration::ZERO;
        for st in stages {
            let d: Duration = r
                .stages
                .iter()
                .filter(|(name, _)| name == st)
                .map(|(_, d)| *d)
                .sum();
            derived += d;
            let _ = write!(s, " {} |", secs(d));
        }
        let _ = writeln!(
            s,
            " {} | {} |",
            secs(r.total.saturating_sub(derived)),
            r.source_bytes / 1024
        );
    }
}

/// The tables of multiplications and of additions per function, each with its growth exponent.
fn render_ops(s: &mut String, rows: &[Row], functions: &[String]) {
    let kinds = [(0, "Multiplications"), (1, "Additions and subtractions")];
    for (k, title) in kinds {
        let _ = writeln!(s, "\n## {title}\n");
        let _ = write!(s, "| n |");
        for f in functions {
            let _ = write!(s, " {f} |");
        }
        let _ = writeln!(s);
        let _ = writeln!(s, "|{}", "---:|".repeat(functions.len() + 1));
        for r in rows {
            let _ = write!(s, "| {} |", r.n);
            for f in functions {
                match r.ops.iter().find(|(g, _)| g == f) {
                    Some((_, o)) => {
                        let _ = write!(s, " {} |", o[k]);
                    }
                    None => s.push_str(" |"),
                }
            }
            let _ = writeln!(s);
        }
        let _ = write!(s, "| growth n^p, p = |");
        for f in functions {
            match exponent(rows, f, k) {
                Some(p) => {
                    let _ = write!(s, " {p:.2} |");
                }
                None => s.push_str(" |"),
            }
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "\nThe last row is the slope of log(count) against log(n) between the largest chain and \
         the one about half as long: 1 is linear growth, 2 quadratic."
    );
}

/// One table of the rarer operations (divisions, square roots, sines, cosines) per function.
fn render_rare_ops(s: &mut String, rows: &[Row], functions: &[String]) {
    // Divisions, square roots, sines and cosines: few, so one cell per function.
    let _ = writeln!(s, "\n## Divisions, square roots, sines and cosines\n");
    let _ = writeln!(s, "Each cell is div / sqrt / sin / cos.\n");
    let _ = write!(s, "| n |");
    for f in functions {
        let _ = write!(s, " {f} |");
    }
    let _ = writeln!(s);
    let _ = writeln!(s, "|{}", "---:|".repeat(functions.len() + 1));
    for r in rows {
        let _ = write!(s, "| {} |", r.n);
        for f in functions {
            match r.ops.iter().find(|(g, _)| g == f) {
                Some((_, o)) => {
                    let _ = write!(s, " {}/{}/{}/{} |", o[2], o[5], o[3], o[4]);
                }
                None => s.push_str(" |"),
            }
        }
        let _ = writeln!(s);
    }
}

/// The command line.
struct Options {
    min: usize,
    max: usize,
    step: usize,
    out: Option<String>,
    keep: Option<String>,
}

fn parse_args() -> Result<Options, String> {
    let mut o = Options {
        min: 2,
        max: 24,
        step: 1,
        out: None,
        keep: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        let number = |v: String| v.parse::<usize>().map_err(|e| format!("{a}: {e}"));
        match a.as_str() {
            "--min" => o.min = number(value()?)?,
            "--max" => o.max = number(value()?)?,
            "--step" => o.step = number(value()?)?,
            "--out" => o.out = Some(value()?),
            "--keep" => o.keep = Some(value()?),
            "-h" | "--help" => {
                return Err(
                    "usage: scaling [--min N] [--max N] [--step N] [--out FILE.md] [--keep DIR]"
                        .into(),
                )
            }
            _ => return Err(format!("unknown argument {a} (try --help)")),
        }
    }
    if o.min < 1 || o.min > o.max || o.step < 1 {
        return Err(format!(
            "need 1 <= --min <= --max and --step >= 1, got {}, {} and {}",
            o.min, o.max, o.step
        ));
    }
    Ok(o)
}

fn main() -> ExitCode {
    let opts = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let dir = match &opts.keep {
        Some(d) => std::path::PathBuf::from(d),
        None => std::env::temp_dir().join(format!("eomgen-scaling-{}", std::process::id())),
    };
    let cleanup = |dir: &std::path::Path| {
        if opts.keep.is_none() {
            let _ = std::fs::remove_dir_all(dir);
        }
    };
    let mut rows = Vec::new();
    for n in (opts.min..=opts.max).step_by(opts.step) {
        eprint!("n = {n} ... ");
        match measure(&dir, n) {
            Ok(r) => {
                eprintln!("{:.2} s", r.total.as_secs_f64());
                rows.push(r);
            }
            Err(e) => {
                eprintln!("failed: {e}");
                cleanup(&dir);
                return ExitCode::FAILURE;
            }
        }
    }
    cleanup(&dir);

    // Functions and stages in the order the generator reports them, whatever they are.
    let mut functions: Vec<String> = Vec::new();
    let mut stages: Vec<&'static str> = Vec::new();
    for r in &rows {
        for (f, _) in &r.ops {
            if !functions.contains(f) {
                functions.push(f.clone());
            }
        }
        for (st, _) in &r.stages {
            if !stages.contains(st) {
                stages.push(st);
            }
        }
    }
    let doc = render(&rows, &functions, &stages);
    match opts.out {
        Some(path) => {
            // Sections measured by other means (scripts/build-cost) follow a marker and stay.
            let kept = std::fs::read_to_string(&path)
                .ok()
                .and_then(|old| old.find(KEEP_MARKER).map(|at| old[at..].to_string()))
                .unwrap_or_default();
            let doc = if kept.is_empty() {
                doc
            } else {
                format!("{doc}\n{kept}")
            };
            if let Err(e) = std::fs::write(&path, doc) {
                eprintln!("{path}: {e}");
                return ExitCode::FAILURE;
            }
            eprintln!("wrote {path}");
        }
        None => print!("{doc}"),
    }
    ExitCode::SUCCESS
}
