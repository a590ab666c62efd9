//! Which evaluation of the equations of motion a stride uses: the planar fast path, the 3D
//! fast path (the axis tree), or the general engine, and whether the stride loop runs on
//! fixed-size states. A stride setting ([`crate::stride::StrideSettings::evaluation`]).

/// Which evaluation of the equations of motion a phase uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EvaluationPath {
    /// The planar fast path when the model qualifies ([`crate::engine::planar::PlanarTree::of`]), else the 3D fast
    /// path when it qualifies ([`crate::engine::axis_tree::AxisTree::of`]), else the general one; and
    /// the fixed-size stride loop where it covers the stride (`crate::stride`'s `fast`).
    #[default]
    Auto,
    /// The planar (or 3D) fast path when the model qualifies, inside the general stride loop
    /// (no fixed-size stride): the reference the fixed-size stride is measured against.
    GeneralLoop,
    /// Always the general 3D engine (the reference the fast paths are tested against).
    General,
    /// As [`Self::Auto`] (the fixed-size stride where it covers the stride), but the planar
    /// evaluation always by its link pass, without the closed forms of particular trees (the
    /// two-link chain's, `planar/two_link.rs`, and the three-link chain's, `planar/three_link.rs`):
    /// what those are measured and tested against.
    LinkPass,
}
