//! A hybrid walker: a model plus its contact, impact, event and relabelling rules (the rules
//! themselves, over the model only, are in `crate::engine::hybrid`), and what it derives from
//! them once (`crate::engine::compiled`). Built by [`Walker::new`] and read-only after: a
//! changed walker is a new one ([`Walker::into_parts`], then [`Walker::new`]).

use crate::engine::compiled::{CompiledWalker, PathStructures};
use crate::engine::events::Direction;
pub use crate::engine::hybrid::heel_strike::{ContactConstraint, HeelStrikeRule};
use crate::engine::model::{CoordIndex, Model, PointIndex};
use crate::engine::relabel::Relabel;
use crate::engine::EvaluationPath;
use nalgebra::DVector;
use std::sync::Arc;

/// A knee with a hyperextension stop that locks after its inelastic impact.
#[derive(Clone, Debug, PartialEq)]
pub struct KneeLock {
    /// The knee coordinate.
    pub coordinate: CoordIndex,
    /// Stop angle \[rad\].
    pub stop_rad: f64,
    /// Direction of `q − stop` that means reaching the stop.
    pub closing: Direction,
}

/// When the walker has fallen.
#[derive(Clone, Debug, PartialEq)]
pub struct FallRule {
    /// A point at the hip.
    pub hip: PointIndex,
    /// Fallen when the hip is lower than this above the floor \[m\].
    pub min_hip_height_m: f64,
}

/// A complete hybrid walker (read-only: see the module's documentation).
#[derive(Clone, Debug)]
pub struct Walker {
    name: String,
    model: Model,
    impact_model: Model,
    heel_strike: HeelStrikeRule,
    knees: Vec<KneeLock>,
    fall: FallRule,
    relabel: Relabel,
    ankle: Option<crate::engine::actuator::AnkleReflex>,
    initially_locked: Vec<CoordIndex>,
    three_d_freedoms: Vec<String>,
    relabel_reference_q: DVector<f64>,
    /// Shared by the walker's clones (the same model and rules): kept out of the walker's
    /// own size, which moves by value.
    compiled: Arc<CompiledWalker>,
}

/// A walker's rules besides its model: what [`Walker::new`] builds a walker from.
#[derive(Clone, Debug)]
pub struct WalkerRules {
    /// Heel strike.
    pub heel_strike: HeelStrikeRule,
    /// Knee locks (empty for straight legs).
    pub knees: Vec<KneeLock>,
    /// Falls.
    pub fall: FallRule,
    /// Relabelling after heel strike (its `fixed` coordinates are set by [`Walker::new`]).
    pub relabel: Relabel,
    /// The stance ankle's stretch reflex, if the walker has one.
    pub ankle: Option<crate::engine::actuator::AnkleReflex>,
    /// Coordinates only the 3D model has (for eigenvalue reports).
    pub three_d_freedoms: Vec<String>,
    /// The relabelling's reference pose ([`Walker::relabel_reference_q`]).
    pub relabel_reference_q: DVector<f64>,
}

impl Walker {
    /// A walker named `name` from its single-stance `model` and its `rules`, without a scene
    /// file: the impact model (the stance contact released as the heel-strike rule says) and
    /// the coordinates locked at the start of a stride (the toe pitch of an ankle reflex's
    /// flat foot, also held by the relabelling) are derived here.
    pub fn new(name: impl Into<String>, model: Model, rules: WalkerRules) -> Self {
        let WalkerRules {
            heel_strike,
            knees,
            fall,
            mut relabel,
            ankle,
            three_d_freedoms,
            relabel_reference_q,
        } = rules;
        let initially_locked: Vec<CoordIndex> = ankle.iter().map(|a| a.toe_pitch).collect();
        relabel.fixed = initially_locked.clone();
        let impact_model = model.with_released_root(&heel_strike.release);
        Self {
            name: name.into(),
            model,
            impact_model,
            heel_strike,
            knees,
            fall,
            relabel,
            ankle,
            initially_locked,
            three_d_freedoms,
            relabel_reference_q,
            compiled: Arc::default(),
        }
    }

    /// The walker's name, model and rules, as [`Walker::new`] takes them (to build a changed
    /// walker from).
    pub fn into_parts(self) -> (String, Model, WalkerRules) {
        let rules = WalkerRules {
            heel_strike: self.heel_strike,
            knees: self.knees,
            fall: self.fall,
            relabel: self.relabel,
            ankle: self.ankle,
            three_d_freedoms: self.three_d_freedoms,
            relabel_reference_q: self.relabel_reference_q,
        };
        (self.name, self.model, rules)
    }

    /// This walker with its model and rules changed by `change`: a new walker
    /// ([`Walker::new`] of the changed parts), its derived structures built again.
    pub fn with_changes(self, change: impl FnOnce(&mut Model, &mut WalkerRules)) -> Self {
        let (name, mut model, mut rules) = self.into_parts();
        change(&mut model, &mut rules);
        Self::new(name, model, rules)
    }

    /// The scene name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The single-stance model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The same model with the stance contact released (for impacts).
    pub fn impact_model(&self) -> &Model {
        &self.impact_model
    }

    /// Heel strike.
    pub fn heel_strike(&self) -> &HeelStrikeRule {
        &self.heel_strike
    }

    /// Knee locks (empty for straight legs).
    pub fn knees(&self) -> &[KneeLock] {
        &self.knees
    }

    /// Falls.
    pub fn fall(&self) -> &FallRule {
        &self.fall
    }

    /// Relabelling after heel strike.
    pub fn relabel(&self) -> &Relabel {
        &self.relabel
    }

    /// The stance ankle's stretch reflex, if the walker has one.
    pub fn ankle(&self) -> Option<&crate::engine::actuator::AnkleReflex> {
        self.ankle.as_ref()
    }

    /// Coordinates locked (at zero) at the start of every stride, e.g. the toe pitch of a flat
    /// stance foot. They are left out of the stride map.
    pub fn initially_locked(&self) -> &[CoordIndex] {
        &self.initially_locked
    }

    /// Coordinates only the 3D model has (for eigenvalue reports).
    pub fn three_d_freedoms(&self) -> &[String] {
        &self.three_d_freedoms
    }

    /// The relabelling's reference pose: the Newton solve that finds the new stance
    /// coordinates after heel strike starts from it (and, failing that, from the pre-impact
    /// pose). Any pose near the walker's stance just after heel strike will do; the scene sets
    /// it to the coordinates of its gait guess. It does not change the solution, only whether
    /// and how fast the solve finds it.
    pub fn relabel_reference_q(&self) -> &DVector<f64> {
        &self.relabel_reference_q
    }

    /// What the walker derives from its model for `path`, built at the first call.
    pub(crate) fn compiled(&self, path: EvaluationPath) -> &PathStructures {
        self.compiled
            .path(&self.model, &self.heel_strike, self.fall.hip, path)
    }

    /// The coordinates that enter the stride map (all but the cyclic ones).
    pub fn map_coordinates(&self) -> Vec<CoordIndex> {
        (0..self.model.dof())
            .map(CoordIndex)
            .filter(|c| !self.relabel.cyclic.contains(c) && !self.initially_locked.contains(c))
            .collect()
    }

    /// Packs `q`, `q̇` into a stride-map vector (positions then velocities, cyclic omitted).
    pub fn pack(&self, q: &DVector<f64>, qd: &DVector<f64>) -> DVector<f64> {
        let c = self.map_coordinates();
        let n = c.len();
        DVector::from_fn(2 * n, |i, _| if i < n { q[c[i].0] } else { qd[c[i - n].0] })
    }

    /// Unpacks a stride-map vector (cyclic coordinates and their rates are zero). A vector of
    /// another length than the map's (another walker's state) unpacks to NaN, which every
    /// stride refuses as a non-finite state; the stride map checks the length first
    /// ([`crate::stride::FailureCause::MapLength`]).
    pub fn unpack(&self, x: &DVector<f64>) -> (DVector<f64>, DVector<f64>) {
        let c = self.map_coordinates();
        let n = c.len();
        let fits = x.len() == 2 * n;
        let at = |i: usize| if fits { x[i] } else { f64::NAN };
        let mut q = DVector::zeros(self.model.dof());
        let mut qd = DVector::zeros(self.model.dof());
        for (i, ci) in c.iter().enumerate() {
            q[ci.0] = at(i);
            qd[ci.0] = at(n + i);
        }
        (q, qd)
    }

    /// Names of the stride-map entries: `coord` then `coord_dot`.
    pub fn map_names(&self) -> Vec<String> {
        let c = self.map_coordinates();
        let mut names: Vec<String> = c
            .iter()
            .map(|ci| self.model.coordinates[ci.0].name.clone())
            .collect();
        names.extend(
            c.iter()
                .map(|ci| format!("{}_dot", self.model.coordinates[ci.0].name)),
        );
        names
    }
}
