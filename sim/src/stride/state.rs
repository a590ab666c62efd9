//! A state of a stride in one storage ([`StrideState`]): what the one stride loop, the
//! witnesses and the energy figures read of a sample, dynamic `DVector` or fixed-size
//! `SVector<N>`.

use crate::engine::integrators::Sample;

/// A state of a stride (stride time, positions, velocities) in one storage.
pub(super) trait StrideState: Clone {
    /// Stride time [s].
    fn t_s(&self) -> f64;
    /// Coordinate `c`.
    fn q(&self, c: usize) -> f64;
    /// The rate of coordinate `c`.
    fn qd(&self, c: usize) -> f64;
    /// Every position and velocity finite.
    fn is_finite(&self) -> bool;
    /// As a general sample (what the stride records and the impacts read).
    fn to_sample(&self) -> Sample;
    /// A general sample in this storage (`None`: another length, or not finite where the
    /// storage requires it).
    fn from_sample(s: Sample) -> Option<Self>;
}

impl StrideState for Sample {
    #[inline]
    fn t_s(&self) -> f64 {
        self.t_s
    }
    #[inline]
    fn q(&self, c: usize) -> f64 {
        self.q[c]
    }
    #[inline]
    fn qd(&self, c: usize) -> f64 {
        self.qd[c]
    }
    fn is_finite(&self) -> bool {
        self.q.iter().chain(self.qd.iter()).all(|v| v.is_finite())
    }
    fn to_sample(&self) -> Sample {
        self.clone()
    }
    fn from_sample(s: Sample) -> Option<Self> {
        Some(s)
    }
}
