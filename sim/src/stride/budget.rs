//! A budget of strides shared by every stride of one search: a gait search on a large model
//! (a compass with 50 extra pendulum links: 209 strides of 30 ms for each Newton Jacobian)
//! can run for hours; with a budget it stops, saying so, and its count shows its progress.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// At most `limit` strides; each stride run with settings that carry the budget takes one
/// ([`SharedBudget`] in [`super::StrideSettings::search_budget`]); when none is left a stride
/// fails at once with [`super::FailureKind::SearchBudgetExhausted`]. Shared between threads
/// (a Jacobian's columns run in parallel).
#[derive(Debug)]
pub struct SearchBudget {
    limit_strides: usize,
    used_strides: AtomicUsize,
    cancelled: AtomicBool,
}

impl SearchBudget {
    /// A budget of `limit_strides` strides.
    pub fn new(limit_strides: usize) -> Self {
        Self {
            limit_strides,
            used_strides: AtomicUsize::new(0),
            cancelled: AtomicBool::new(false),
        }
    }

    /// The limit \[strides\].
    pub fn limit_strides(&self) -> usize {
        self.limit_strides
    }

    /// Strides taken so far (for progress).
    pub fn used_strides(&self) -> usize {
        self.used_strides.load(Ordering::Relaxed)
    }

    /// Spends the budget: every later [`Self::take`] fails, so the search stops at its next
    /// stride as if the budget had run out.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Whether [`Self::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }

    /// Takes one stride: `false` when none is left or the budget was cancelled (and nothing
    /// is taken).
    pub fn take(&self) -> bool {
        if self.is_cancelled() {
            return false;
        }
        self.used_strides
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |u| {
                (u < self.limit_strides).then_some(u + 1)
            })
            .is_ok()
    }
}

/// A [`SearchBudget`] shared by the settings of one search, or none (no limit but each
/// stride's own). Not part of what the settings mean: two settings that differ only in their
/// budget compare equal, and it is not serialised.
#[derive(Clone, Debug, Default)]
pub struct SharedBudget(pub Option<Arc<SearchBudget>>);

impl SharedBudget {
    /// Takes one stride from the budget, if there is one: `Err(limit)` when it is spent.
    pub fn take(&self) -> Result<(), usize> {
        match &self.0 {
            Some(b) if !b.take() => Err(b.limit_strides()),
            _ => Ok(()),
        }
    }
}

impl PartialEq for SharedBudget {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_budget_gives_exactly_its_limit_across_threads() {
        let b = Arc::new(SearchBudget::new(1000));
        let taken: usize = std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|_| s.spawn(|| (0..600).filter(|_| b.take()).count()))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap_or(0)).sum()
        });
        assert_eq!(taken, 1000);
        assert_eq!(b.used_strides(), 1000);
        let shared = SharedBudget(Some(b));
        assert_eq!(shared.take(), Err(1000));
        assert_eq!(SharedBudget::default().take(), Ok(()));
    }

    #[test]
    fn a_cancelled_budget_gives_nothing_more() {
        let b = SearchBudget::new(10);
        assert!(b.take());
        b.cancel();
        assert!(!b.take());
        assert_eq!(b.used_strides(), 1);
        assert!(b.is_cancelled());
    }
}
