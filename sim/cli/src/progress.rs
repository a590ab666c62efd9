//! Progress of a long study on a terminal: a bar on standard error with a label, the count
//! done out of a length, the time taken and the time left. Silent when the output is JSON or
//! standard error is not a terminal (a pipe, a file, a test), so it never mixes into what
//! another tool reads. Generic: any command that knows how many pieces of work it has (points,
//! grid cells, values) can show one.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// A progress bar (or nothing, when silent). Shared between threads: [`Self::tick`] may be
/// called from any of them.
pub struct Progress {
    bar: ProgressBar,
    len: u64,
}

impl Progress {
    /// A bar of `len` pieces labelled `label`, shown only when `visible` and standard error is
    /// a terminal (pass `!json`).
    pub fn new(len: usize, label: &str, visible: bool) -> Self {
        let len = u64::try_from(len).unwrap_or(u64::MAX);
        let bar = if visible && std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(
                "{msg} [{bar:32}] {pos}/{len} ({elapsed} taken, about {eta} left)",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_message(label.to_string());
            bar
        } else {
            ProgressBar::hidden()
        };
        Self { bar, len }
    }

    /// One more piece done.
    pub fn tick(&self) {
        self.bar.inc(1);
    }

    /// Sets the count done to `fraction` (0 to 1) of the length, for work that reports a
    /// fraction rather than pieces; it never moves the bar back.
    pub fn set_fraction(&self, fraction: f64) {
        let pos = (fraction.clamp(0.0, 1.0) * self.len as f64).round() as u64;
        if pos > self.bar.position() {
            self.bar.set_position(pos);
        }
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hidden_bar_counts_without_drawing() {
        let p = Progress::new(3, "test", false);
        for _ in 0..5 {
            p.tick();
        }
        assert!(p.bar.is_hidden());
        assert_eq!(p.bar.position(), 5);
        p.finish();
    }

    #[test]
    fn a_fraction_sets_the_position_and_never_moves_back() {
        let p = Progress::new(1000, "test", false);
        p.set_fraction(0.25);
        assert_eq!(p.bar.position(), 250);
        p.set_fraction(0.1);
        assert_eq!(p.bar.position(), 250);
        p.set_fraction(7.0);
        assert_eq!(p.bar.position(), 1000);
        p.set_fraction(f64::NAN);
        assert_eq!(p.bar.position(), 1000);
    }
}
