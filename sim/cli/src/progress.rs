//! Progress of a long study on a terminal: a bar on standard error with a label, the count
//! done out of a length, the time taken and the time left. Silent when the output is JSON or
//! standard error is not a terminal (a pipe, a file, a test), so it never mixes into what
//! another tool reads. Generic: any command that knows how many pieces of work it has (points,
//! grid cells, values) can show one.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A progress bar (or nothing, when silent). Shared between threads: [`Self::tick`] may be
/// called from any of them.
pub struct Progress {
    bar: ProgressBar,
    len: u64,
    /// A bar made with [`Self::after`] that is not drawn yet: drawn from the first tick at or
    /// after this instant.
    shown_from: Option<Instant>,
    /// Whether the delayed bar is already drawn.
    drawn: AtomicBool,
}

impl Progress {
    /// A bar of `len` pieces labelled `label`, shown only when `visible` and standard error is
    /// a terminal (pass `!json`).
    pub fn new(len: usize, label: &str, visible: bool) -> Self {
        Self::build(len, label, visible, None)
    }

    /// As [`Self::new`], but the bar appears only once the work has lasted `delay` (at its
    /// first tick after that): work that ends sooner leaves the terminal untouched. For walks
    /// (`walker walk`, `walker sil`), whose length is only known as they go.
    pub fn after(delay: Duration, len: usize, label: &str, visible: bool) -> Self {
        Self::build(len, label, visible, Some(delay))
    }

    /// The bar, drawn on standard error at once (`delay` `None`) or from its first tick after
    /// `delay`, or hidden when not `visible` or standard error is not a terminal.
    fn build(len: usize, label: &str, visible: bool, delay: Option<Duration>) -> Self {
        let len = u64::try_from(len).unwrap_or(u64::MAX);
        let shown = visible && std::io::stderr().is_terminal();
        let bar = if shown {
            // A delayed bar starts without a target: nothing is drawn before its time.
            let target = match delay {
                None => ProgressDrawTarget::stderr(),
                Some(_) => ProgressDrawTarget::hidden(),
            };
            let bar = ProgressBar::with_draw_target(Some(len), target);
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
        let shown_from = delay
            .filter(|_| shown)
            .and_then(|d| Instant::now().checked_add(d));
        Self {
            bar,
            len,
            drawn: AtomicBool::new(shown_from.is_none()),
            shown_from,
        }
    }

    /// One more piece done.
    pub fn tick(&self) {
        self.bar.inc(1);
        if let Some(from) = self.shown_from {
            if !self.drawn.load(Ordering::Relaxed)
                && Instant::now() >= from
                && !self.drawn.swap(true, Ordering::Relaxed)
            {
                self.bar.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
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
    fn a_delayed_silent_bar_stays_hidden_and_counts() {
        let p = Progress::after(Duration::ZERO, 4, "walk", false);
        p.tick();
        p.tick();
        assert!(p.bar.is_hidden());
        assert_eq!(p.bar.position(), 2);
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
