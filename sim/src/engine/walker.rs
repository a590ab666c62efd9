//! A hybrid walker: a model plus its contact, impact, event and relabelling rules (the rules
//! themselves, over the model only, are in `crate::engine::hybrid`).

use crate::engine::events::Direction;
pub use crate::engine::hybrid::heel_strike::{ContactConstraint, HeelStrikeRule};
use crate::engine::model::{CoordIndex, Model, PointIndex};
use crate::engine::relabel::Relabel;
use nalgebra::DVector;

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

/// A complete hybrid walker.
#[derive(Clone, Debug)]
pub struct Walker {
    /// The scene name.
    pub name: String,
    /// The single-stance model.
    pub model: Model,
    /// The same model with the stance contact released (for impacts).
    pub impact_model: Model,
    /// Heel strike.
    pub heel_strike: HeelStrikeRule,
    /// Knee locks (empty for straight legs).
    pub knees: Vec<KneeLock>,
    /// Falls.
    pub fall: FallRule,
    /// Relabelling after heel strike.
    pub relabel: Relabel,
    /// The stance ankle's stretch reflex, if the walker has one.
    pub ankle: Option<crate::engine::actuator::AnkleReflex>,
    /// Coordinates locked (at zero) at the start of every stride, e.g. the toe pitch of a flat
    /// stance foot. They are left out of the stride map.
    pub initially_locked: Vec<CoordIndex>,
    /// Coordinates only the 3D model has (for eigenvalue reports).
    pub three_d_freedoms: Vec<String>,
    /// The relabelling's reference pose: the Newton solve that finds the new stance
    /// coordinates after heel strike starts from it (and, failing that, from the pre-impact
    /// pose). Any pose near the walker's stance just after heel strike will do; the scene sets
    /// it to the coordinates of its gait guess. It does not change the solution, only whether
    /// and how fast the solve finds it.
    pub relabel_reference_q: DVector<f64>,
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
        }
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

    /// Unpacks a stride-map vector (cyclic coordinates and their rates are zero).
    pub fn unpack(&self, x: &DVector<f64>) -> (DVector<f64>, DVector<f64>) {
        let c = self.map_coordinates();
        let n = c.len();
        let mut q = DVector::zeros(self.model.dof());
        let mut qd = DVector::zeros(self.model.dof());
        for (i, ci) in c.iter().enumerate() {
            q[ci.0] = x[i];
            qd[ci.0] = x[n + i];
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
