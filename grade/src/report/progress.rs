//! The progress of the grader's long commands as people see it: a bar on a terminal; elsewhere
//! (CI, Gradescope, a pipe), where indicatif draws nothing, its message as a line when it changes
//! and every 10 s while it does not, so a log is never silent for long.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// A progress bar for the grader's long commands, drawn on a terminal. Elsewhere (CI,
/// Gradescope, a pipe), where indicatif draws nothing, its message is printed as a line when it
/// changes and every 10 s while it does not, so a log is never silent for long.
pub fn progress_bar(length: u64) -> ProgressBar {
    let style =
        ProgressStyle::with_template("{spinner} [{bar:30}] {pos}/{len} {msg}").expect("a valid template");
    let bar = ProgressBar::new(length).with_style(style.progress_chars("=> "));
    if !std::io::stderr().is_terminal() {
        let watched = bar.clone();
        std::thread::spawn(move || {
            let (mut last, mut since) = (String::new(), Instant::now());
            while !watched.is_finished() {
                let message = watched.message();
                let step = format!("[{}/{}]", watched.position(), watched.length().unwrap_or(0));
                if !message.is_empty() && (message != last || since.elapsed() >= Duration::from_secs(10)) {
                    let still = if message == last { "still " } else { "" };
                    eprintln!("grader: {step} {still}{message} ({:.0} s)", watched.elapsed().as_secs_f64());
                    (last, since) = (message, Instant::now());
                }
                std::thread::sleep(Duration::from_millis(250));
            }
        });
    }
    bar
}
