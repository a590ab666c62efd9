//! Bounded histories: a long run (a 10,000-step soak) keeps the first and the most recent
//! entries of each history, up to a capacity, and counts the ones it left out.

use std::collections::VecDeque;

/// The first `capacity / 2` entries and the most recent `capacity − capacity / 2`, with a
/// count of the entries elided between them.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundedLog<T> {
    head: Vec<T>,
    tail: VecDeque<T>,
    head_capacity: usize,
    tail_capacity: usize,
    elided: u64,
}

impl<T: Clone> BoundedLog<T> {
    /// A log of at most `capacity` entries (0 keeps none and counts every entry elided).
    pub fn new(capacity: usize) -> Self {
        let head_capacity = capacity / 2;
        BoundedLog {
            head: Vec::new(),
            tail: VecDeque::new(),
            head_capacity,
            tail_capacity: capacity - head_capacity,
            elided: 0,
        }
    }

    /// Append an entry; once the log is full the oldest entry after the head is elided.
    pub fn push(&mut self, entry: T) {
        if self.head.len() < self.head_capacity {
            self.head.push(entry);
            return;
        }
        if self.tail_capacity == 0 {
            self.elided += 1;
            return;
        }
        if self.tail.len() >= self.tail_capacity {
            self.tail.pop_front();
            self.elided += 1;
        }
        self.tail.push_back(entry);
    }

    /// Entries kept.
    pub fn len(&self) -> usize {
        self.head.len() + self.tail.len()
    }

    /// No entry kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Entries elided (pushed, then dropped to keep the log bounded).
    pub fn elided(&self) -> u64 {
        self.elided
    }

    /// The entries kept, oldest first (the head, then the most recent ones).
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        self.head.iter().chain(self.tail.iter())
    }

    /// The entries kept, as a vector.
    pub fn to_vec(&self) -> Vec<T> {
        self.iter().cloned().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_first_and_the_latest_and_counts_the_rest() {
        let mut log = BoundedLog::new(5);
        for k in 0..4 {
            log.push(k);
        }
        assert_eq!((log.to_vec(), log.elided()), (vec![0, 1, 2, 3], 0));
        for k in 4..20 {
            log.push(k);
        }
        assert_eq!(log.to_vec(), vec![0, 1, 17, 18, 19]);
        assert_eq!(log.elided(), 15);
        assert_eq!(log.len(), 5);
        let mut none = BoundedLog::new(0);
        none.push(1);
        assert!(none.is_empty());
        assert_eq!(none.elided(), 1);
        let mut one = BoundedLog::new(1);
        one.push(1);
        one.push(2);
        assert_eq!((one.to_vec(), one.elided()), (vec![2], 1));
    }
}
