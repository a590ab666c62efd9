//! Progress of one long gait search on a terminal: the strides its budget has given out, of
//! how many, and the time taken, drawn once the search has lasted a second (a compass with 50
//! extra links printed nothing for minutes). Silent when the output is JSON or standard error
//! is not a terminal. A thread reads the budget's count: the search itself is not touched.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sim::stride::SearchBudget;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The search must last this long before its progress is drawn.
const DELAY: Duration = Duration::from_secs(1);
/// How often the count is read.
const POLL: Duration = Duration::from_millis(100);

/// Watches a budget until dropped.
pub struct SearchProgress {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl SearchProgress {
    /// Shows `budget`'s strides as `label`'s progress when `visible` (pass `!json`) and
    /// standard error is a terminal.
    pub fn watch(budget: &Arc<SearchBudget>, label: &str, visible: bool) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let thread = (visible && std::io::stderr().is_terminal())
            .then(|| {
                let (stop, budget) = (Arc::clone(&stop), Arc::clone(budget));
                let label = label.to_owned();
                std::thread::Builder::new()
                    .name("search-progress".into())
                    .spawn(move || draw(&stop, &budget, label))
                    .ok()
            })
            .flatten();
        Self { stop, thread }
    }
}

fn draw(stop: &AtomicBool, budget: &SearchBudget, label: String) {
    let start = Instant::now();
    let limit = u64::try_from(budget.limit_strides()).unwrap_or(u64::MAX);
    let mut bar: Option<ProgressBar> = None;
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(POLL);
        if bar.is_none() && start.elapsed() >= DELAY {
            let b = ProgressBar::with_draw_target(Some(limit), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(
                "{msg} [{bar:32}] {pos}/{len} strides of its budget (--max-strides), {elapsed} taken",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            b.set_message(label.clone());
            bar = Some(b);
        }
        if let Some(b) = &bar {
            b.set_position(u64::try_from(budget.used_strides()).unwrap_or(u64::MAX));
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
}

impl Drop for SearchProgress {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The gait of `scene` by the one gait rule ([`sim::analysis::homotopy::GaitRule`]) as a
/// command asks for it: each setup built by `setup_for`, the options' Newton and homotopy
/// settings, a budget of `--max-strides` strides and its progress on a terminal after a second
/// (not with `--json`). The gait and where it came from, or why there is none.
///
/// # Errors
/// A scene that cannot be built at the values the rule visits.
pub fn rule_gait(
    common: &crate::options::Common,
    setup_for: &sim::analysis::homotopy::SetupFor<'_>,
    scene: &sim::scene::Scene,
) -> Result<
    Result<
        (
            sim::analysis::limit_cycle::Gait,
            sim::analysis::homotopy::GaitSource,
        ),
        sim::analysis::limit_cycle::NewtonError,
    >,
    sim::scene::SceneError,
> {
    let budget = Arc::new(SearchBudget::new(common.max_strides));
    let _progress = SearchProgress::watch(&budget, "gait search", !common.json);
    sim::analysis::homotopy::GaitRule::new(setup_for, &common.newton(), &common.homotopy())
        .with_budget(Arc::clone(&budget))
        .gait(scene)
}
