//! What a walker derives from its model, once per walker ([`CompiledWalker`]): for each
//! [`EvaluationPath`], the planar tree (with its closed form), the 3D axis tree and the
//! planar points its stride events follow. Built at the first stride that asks for a path,
//! kept by the walker (whose model and rules cannot change after [`Walker::new`]), and read by
//! every stride, workspace and thread after it: pinocchio's `Model` to the workspaces' `Data`.
//!
//! [`Walker::new`]: crate::engine::walker::Walker::new

use crate::engine::axis_tree::AxisTree;
use crate::engine::hybrid::heel_strike::HeelStrikeRule;
use crate::engine::model::{Model, PointIndex};
use crate::engine::planar::{PlanarPoints, PlanarTree};
use crate::engine::EvaluationPath;
use std::sync::OnceLock;

/// The structures of one evaluation path.
#[derive(Clone, Debug)]
pub(crate) struct PathStructures {
    /// The planar tree, when the model qualifies and the path allows it.
    pub(crate) planar: Option<PlanarTree>,
    /// The 3D axis tree, when the model is not planar but qualifies and the path allows it.
    pub(crate) axis_tree: Option<AxisTree>,
    /// The points the fixed-size stride's witnesses follow, on the planar tree of 1 to
    /// `MAX_PLANAR_COORDINATES` coordinates.
    pub(crate) planar_points: Option<PlanarPoints>,
}

impl PathStructures {
    /// The trees `path` selects for `model` (no planar points): what a phase evaluates on.
    pub(crate) fn trees(model: &Model, path: EvaluationPath) -> Self {
        let planar = PlanarTree::for_path(model, path);
        let axis_tree = match (&planar, path) {
            (
                None,
                EvaluationPath::Auto | EvaluationPath::GeneralLoop | EvaluationPath::LinkPass,
            ) => AxisTree::of(model),
            _ => None,
        };
        Self {
            planar,
            axis_tree,
            planar_points: None,
        }
    }

    /// The trees of `path` and the planar points of `heel_strike`'s feet and the point `hip`.
    fn of(
        model: &Model,
        heel_strike: &HeelStrikeRule,
        hip: PointIndex,
        path: EvaluationPath,
    ) -> Self {
        let mut s = Self::trees(model, path);
        s.planar_points = s.planar.as_ref().and_then(|tree| match tree.dof() {
            1 => PlanarPoints::new::<1>(model, heel_strike, hip, tree),
            2 => PlanarPoints::new::<2>(model, heel_strike, hip, tree),
            3 => PlanarPoints::new::<3>(model, heel_strike, hip, tree),
            4 => PlanarPoints::new::<4>(model, heel_strike, hip, tree),
            5 => PlanarPoints::new::<5>(model, heel_strike, hip, tree),
            6 => PlanarPoints::new::<6>(model, heel_strike, hip, tree),
            _ => None,
        });
        s
    }
}

/// Every evaluation path's structures, each built on first use.
#[derive(Clone, Debug, Default)]
pub(crate) struct CompiledWalker {
    auto: OnceLock<PathStructures>,
    general_loop: OnceLock<PathStructures>,
    general: OnceLock<PathStructures>,
    link_pass: OnceLock<PathStructures>,
}

impl CompiledWalker {
    /// The structures of `path` (built now if no stride asked for them before).
    pub(crate) fn path(
        &self,
        model: &Model,
        heel_strike: &HeelStrikeRule,
        hip: PointIndex,
        path: EvaluationPath,
    ) -> &PathStructures {
        let slot = match path {
            EvaluationPath::Auto => &self.auto,
            EvaluationPath::GeneralLoop => &self.general_loop,
            EvaluationPath::General => &self.general,
            EvaluationPath::LinkPass => &self.link_pass,
        };
        slot.get_or_init(|| PathStructures::of(model, heel_strike, hip, path))
    }
}
