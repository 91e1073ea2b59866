//! A progress line on stderr for long derivations, shown only on a terminal.

use std::io::{IsTerminal, Write};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Runs `work`; when stderr is a terminal and `work` takes longer than a second, shows
/// `eomgen: <label>… 2.4 s` on stderr, updated in place, and erases it at the end. Nothing is
/// written when stderr is piped or redirected.
pub fn run<T>(label: &str, work: impl FnOnce() -> T) -> T {
    if !std::io::stderr().is_terminal() {
        return work();
    }
    let (done, wait) = mpsc::channel::<()>();
    let label = label.to_string();
    let ticker = std::thread::spawn(move || {
        let start = Instant::now();
        let mut shown = false;
        loop {
            let timeout = if shown {
                Duration::from_millis(200)
            } else {
                Duration::from_secs(1)
            };
            match wait.recv_timeout(timeout) {
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    shown = true;
                    let secs = start.elapsed().as_secs_f64();
                    let mut e = std::io::stderr().lock();
                    let _ = write!(e, "\r\x1b[Keomgen: {label}… {secs:.1} s");
                    let _ = e.flush();
                }
                // Finished (or the sender is gone): erase the line.
                _ => {
                    if shown {
                        let mut e = std::io::stderr().lock();
                        let _ = write!(e, "\r\x1b[K");
                        let _ = e.flush();
                    }
                    return;
                }
            }
        }
    });
    let out = work();
    let _ = done.send(());
    let _ = ticker.join();
    out
}
