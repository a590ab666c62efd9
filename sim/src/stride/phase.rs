//! The smooth dynamics of one phase of a stride: which coordinates are free, which one is
//! driven and how ([`Drive`]), and the stability limit of eq. (12) for fixed-step integrators.

use crate::engine::actuator::AnkleProfile;
use crate::engine::axis_tree::AxisTree;
use crate::engine::compiled::PathStructures;
use crate::engine::control::ActuatorSegment;
use crate::engine::dynamics::{Dynamics, DynamicsError};
use crate::engine::hybrid::phase::DriveValues;
use crate::engine::integrators::{Sample, SecondOrderSystem, StabilityLimit};
use crate::engine::model::{CoordIndex, Model};
use crate::engine::planar::PlanarTree;
use crate::engine::walker::Walker;
use crate::stride::EvaluationPath;
use nalgebra::{DMatrix, DVector};

/// How a driven coordinate moves (times are from the start of the stride).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The ideal actuator's smooth extension.
    Profile(AnkleProfile),
    /// A controller's actuator over the current control tick.
    Segment(ActuatorSegment),
}

impl Drive {
    /// Angle \[rad\], rate [rad/s], acceleration [rad/s²] at stride time `t_stride_s` \[s\].
    pub fn eval(&self, t_stride_s: f64) -> (f64, f64, f64) {
        match self {
            Drive::Profile(p) => p.eval(t_stride_s),
            Drive::Segment(s) => s.eval(t_stride_s),
        }
    }
}

/// The smooth dynamics of one phase (which coordinates are free).
pub struct Phase<'a> {
    model: &'a Model,
    dynamics: Dynamics,
    /// The planar fast path, when the model qualifies and the settings allow it.
    planar: Option<PlanarTree>,
    /// The 3D fast path, when the model is not planar but qualifies and the settings allow it.
    axis_tree: Option<AxisTree>,
    /// Which coordinates are free to move.
    pub active: Vec<bool>,
    /// A coordinate driven along a profile (not free, not locked).
    pub prescribed: Option<(CoordIndex, Drive)>,
    /// Scratch for a driven evaluation: `q`, `q̇` with the drive's angle and rate put in, and
    /// the prescribed accelerations (zero but the driven coordinate's).
    driven: (DVector<f64>, DVector<f64>, DVector<f64>),
    /// Which evaluation made the workspace's assembly ([`Assembly`]).
    assembly: Assembly,
}

/// Which use of the evaluation's workspace (the 3D fast path's tree, or else the general
/// engine's) made its assembly, stated, never found by comparing states: every evaluation, and
/// anything else that writes the workspace, is numbered (the epoch); an evaluation that
/// assembles records its epoch and its free set. A caller that knows it is at the state of
/// that evaluation — an integrator at the end of a step whose last stage was that evaluation
/// (first same as last), after a tick whose drive continues the last one's angle and rate to
/// the bit — names the epoch, and the phase solves on that assembly instead of assembling
/// again (`M̄`, `f̄` depend on `q`, `q̇` only, not on the drive's acceleration: the same
/// result to the bit) if nothing used the workspace since.
#[derive(Clone, Debug, Default)]
struct Assembly {
    /// Uses of the workspace so far.
    epoch: u64,
    /// The epoch of the evaluation that made the workspace's assembly, if the last use left
    /// one to solve on.
    made_at: Option<u64>,
    /// The free set of that assembly.
    active: Vec<bool>,
    /// How many evaluations (accelerations or the actuator torque) solved on an assembly
    /// instead of assembling again (what the tests read to know the stage was skipped).
    reuses: u64,
}

impl Assembly {
    /// A new use of the workspace that leaves no assembly to solve on (yet).
    fn next_use(&mut self) {
        self.epoch += 1;
        self.made_at = None;
    }

    /// The assembly of evaluation `epoch` with free set `active`, if it is the workspace's
    /// last use.
    fn is_of(&self, epoch: u64, active: &[bool]) -> bool {
        self.made_at == Some(epoch) && self.epoch == epoch && self.active == active
    }

    /// The current use assembled with free set `active`.
    fn made(&mut self, active: &[bool]) {
        self.made_at = Some(self.epoch);
        self.active.clear();
        self.active.extend_from_slice(active);
    }
}

/// Fills `driven` (`q`, `q̇`, prescribed `q̈`, each of `q`'s length) for an evaluation under
/// `drive`: `q`, `q̇` with the driven coordinate's angle and rate put in, and the prescribed
/// accelerations zero but the driven coordinate's.
fn put_drive(
    driven: &mut (DVector<f64>, DVector<f64>, DVector<f64>),
    q: &DVector<f64>,
    qd: &DVector<f64>,
    drive: &DriveValues<f64>,
) {
    let (dq, dqd, qdd_p) = driven;
    dq.copy_from(q);
    dqd.copy_from(qd);
    dq[drive.coordinate] = drive.angle_rad;
    dqd[drive.coordinate] = drive.rate_rad_s;
    qdd_p.as_mut_slice().fill(0.0);
    qdd_p[drive.coordinate] = drive.acceleration_rad_s2;
}

/// An evaluation that keeps its assembly (to solve on it again: `Phase::solve_on_assembly_of`):
/// the general engine's workspace or the 3D fast path's tree.
trait Assembler {
    /// `q̈` by a (partial) assembly at (`q`, `q̇`) and its solve; `driven`, a coordinate whose
    /// row the assembly computes too, where the evaluation can.
    #[allow(clippy::too_many_arguments)]
    fn assemble_and_solve(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        driven: Option<usize>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError>;
}

impl Assembler for Dynamics {
    fn assemble_and_solve(
        &mut self,
        model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        _driven: Option<usize>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        self.accelerations_of_free_into(model, q, qd, active, qdd_prescribed, out)
    }
}

impl Assembler for AxisTree {
    fn assemble_and_solve(
        &mut self,
        _model: &Model,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        active: &[bool],
        qdd_prescribed: Option<&DVector<f64>>,
        driven: Option<usize>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        self.accelerations_into(q, qd, active, qdd_prescribed, driven, out)
    }
}

/// `q̈` by `assembler`'s partial assembly at (`q`, `q̇`), recorded in `assembly`.
#[allow(clippy::too_many_arguments)]
fn accelerations_of_free<A: Assembler>(
    model: &Model,
    assembler: &mut A,
    assembly: &mut Assembly,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    active: &[bool],
    qdd_prescribed: Option<&DVector<f64>>,
    driven: Option<usize>,
    out: &mut DVector<f64>,
) -> Result<(), DynamicsError> {
    assembly.next_use();
    assembler.assemble_and_solve(model, q, qd, active, qdd_prescribed, driven, out)?;
    assembly.made(active);
    Ok(())
}

impl<'a> Phase<'a> {
    /// All coordinates active; the planar fast path when the model qualifies.
    pub fn new(model: &'a Model) -> Self {
        Self::with_path(model, EvaluationPath::Auto)
    }

    /// All coordinates active, evaluated along `path` (the trees built here).
    pub fn with_path(model: &'a Model, path: EvaluationPath) -> Self {
        Self::on_trees(model, PathStructures::trees(model, path))
    }

    /// All coordinates active, evaluated along `path` on copies of the trees `walker`
    /// compiled once.
    pub(crate) fn of_walker(walker: &'a Walker, path: EvaluationPath) -> Self {
        Self::on_trees(walker.model(), walker.compiled(path).clone())
    }

    /// All coordinates active, evaluated on `trees`.
    fn on_trees(model: &'a Model, trees: PathStructures) -> Self {
        let PathStructures {
            planar, axis_tree, ..
        } = trees;
        Self {
            model,
            dynamics: Dynamics::new(model),
            planar,
            axis_tree,
            active: vec![true; model.dof()],
            prescribed: None,
            driven: (
                DVector::zeros(model.dof()),
                DVector::zeros(model.dof()),
                DVector::zeros(model.dof()),
            ),
            assembly: Assembly::default(),
        }
    }

    /// Back to the start of a stride: every coordinate free, none driven, no assembly to
    /// solve on again.
    pub(crate) fn restart(&mut self) {
        self.active.iter_mut().for_each(|a| *a = true);
        self.prescribed = None;
        self.assembly.next_use();
    }

    /// Puts the prescribed coordinate of `s` exactly on its profile.
    pub fn snap(&self, s: &mut Sample) {
        if let Some((c, p)) = &self.prescribed {
            let (a, ad, _) = p.eval(s.t_s);
            s.q[c.0] = a;
            s.qd[c.0] = ad;
        }
    }

    /// The generalised force [N·m] the prescribed coordinate's actuator exerts at `s`, and the
    /// coordinate's rate: their product is the actuator power. `assembled`: the epoch of the
    /// evaluation made at `s` (as evaluated, the drive's angle and rate put in), when the
    /// caller knows one (the last stage of the step that ended at `s`): the torque is then
    /// solved on its assembly.
    pub fn actuator_torque(
        &mut self,
        s: &Sample,
        assembled: Option<u64>,
    ) -> Result<(f64, f64), DynamicsError> {
        let Some((c, _)) = self.prescribed else {
            return Ok((0.0, 0.0));
        };
        if let Some(tau) = self.torque_on_assembly(s, assembled)? {
            return Ok((tau, s.qd[c.0]));
        }
        if self.axis_tree.is_some() {
            // The 3D fast path's evaluation assembles the driven row too: the torque on it.
            let mut qdd = DVector::zeros(s.q.len());
            self.accelerations_into(s.t_s, &s.q, &s.qd, &mut qdd)?;
            if let Some(tau) = self
                .axis_tree
                .as_ref()
                .and_then(|t| t.actuator_force(c.0, &qdd))
            {
                return Ok((tau, s.qd[c.0]));
            }
        }
        // The general path: its workspace keeps the assembled M̄ and f̄ read below.
        let qdd = self.general_accelerations(s.t_s, &s.q, &s.qd)?;
        let m = &self.dynamics.mass_matrix;
        let tau = (m.row(c.0) * &qdd)[(0, 0)] - self.dynamics.force[c.0];
        Ok((tau, s.qd[c.0]))
    }

    /// The actuator torque at `s` from the assembly of evaluation `epoch` (made at `s`), when
    /// that is the workspace's last use and it computed the driven coordinate's row. The same
    /// arithmetic as the general path (its `q̈` the same to the bit; the row's entries the
    /// assembly skipped are those of locked coordinates, whose `q̈` is zero). `None`
    /// otherwise.
    fn torque_on_assembly(
        &mut self,
        s: &Sample,
        epoch: Option<u64>,
    ) -> Result<Option<f64>, DynamicsError> {
        let (Some(epoch), Some((c, _))) = (epoch, self.prescribed) else {
            return Ok(None);
        };
        if self.axis_tree.is_none() && !self.dynamics.assembled_row(c.0) {
            return Ok(None);
        }
        let mut qdd = DVector::zeros(s.q.len());
        if !self.solve_on_assembly_of(epoch, s.t_s, &mut qdd)? {
            return Ok(None);
        }
        Ok(match self.axis_tree.as_ref() {
            Some(t) => t.actuator_force(c.0, &qdd),
            None => {
                let m = &self.dynamics.mass_matrix;
                Some((m.row(c.0) * &qdd)[(0, 0)] - self.dynamics.force[c.0])
            }
        })
    }

    /// `q̈` into `out` by a solve on the assembly of evaluation `epoch`, with the drive's
    /// prescribed acceleration at `t` [s]: `false` (nothing written) unless that assembly is
    /// the workspace's last use, with the current free set (the planar path keeps none).
    fn solve_on_assembly_of(
        &mut self,
        epoch: u64,
        t: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, DynamicsError> {
        if self.planar.is_some()
            || !self.assembly.is_of(epoch, &self.active)
            || self.driven.2.len() != out.len()
        {
            return Ok(false);
        }
        let qdd_p = match self.drive_at(t) {
            None => None,
            Some(d) => {
                let qdd_p = &mut self.driven.2;
                qdd_p.as_mut_slice().fill(0.0);
                qdd_p[d.coordinate] = d.acceleration_rad_s2;
                Some(&self.driven.2)
            }
        };
        let solved = match self.axis_tree.as_mut() {
            Some(tree) => tree.accelerations_on_assembly_into(&self.active, qdd_p, out)?,
            None => self
                .dynamics
                .accelerations_on_assembly_into(&self.active, qdd_p, out)?,
        };
        if solved {
            self.assembly.reuses += 1;
        }
        Ok(solved)
    }

    /// Whether this phase evaluates along the planar fast path.
    pub fn is_planar_fast_path(&self) -> bool {
        self.planar.is_some()
    }

    /// Whether this phase evaluates along the 3D fast path ([`AxisTree`]).
    pub fn is_axis_tree_fast_path(&self) -> bool {
        self.axis_tree.is_some()
    }

    /// The drive's prescribed motion at `t` [s], if a coordinate is driven.
    fn drive_at(&self, t: f64) -> Option<DriveValues<f64>> {
        self.prescribed.map(|(c, p)| {
            let (angle_rad, rate_rad_s, acceleration_rad_s2) = p.eval(t);
            DriveValues {
                coordinate: c.0,
                angle_rad,
                rate_rad_s,
                acceleration_rad_s2,
            }
        })
    }

    /// `q̈` by the general engine, whatever the path.
    fn general_accelerations(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError> {
        let drive = self.drive_at(t);
        self.assembly.next_use();
        crate::engine::hybrid::phase::accelerations(
            self.model,
            &mut self.dynamics,
            &self.active,
            drive.as_ref(),
            q,
            qd,
        )
    }
}

impl SecondOrderSystem for Phase<'_> {
    fn accelerations(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Result<DVector<f64>, DynamicsError> {
        match &self.planar {
            Some(p) => {
                let drive = self.drive_at(t);
                self.assembly.next_use();
                p.accelerations(&mut self.dynamics, &self.active, drive.as_ref(), q, qd)
            }
            // (`accelerations_into` takes the fast path for these lengths, not this method.)
            None if self.axis_tree.is_some() && self.driven.0.len() == q.len() => {
                let mut out = DVector::zeros(q.len());
                self.accelerations_into(t, q, qd, &mut out)?;
                Ok(out)
            }
            None => self.general_accelerations(t, q, qd),
        }
    }

    fn accelerations_into(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        out: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        match &self.planar {
            Some(p) if out.len() == q.len() => {
                let drive = self.drive_at(t);
                self.assembly.next_use();
                p.accelerations_into(&mut self.dynamics, &self.active, drive.as_ref(), q, qd, out)
            }
            // The 3D fast path's or the general engine's solve straight into `out` (the latter
            // with the arithmetic of `hybrid::phase::accelerations`), without allocating,
            // assembling only what the solve reads (the workspace's `M̄`, `f̄` are partial
            // afterwards: whatever reads the general engine's, `actuator_torque` and
            // `linearised_limit`, assembles again).
            None if out.len() == q.len() && self.driven.0.len() == q.len() => {
                let drive = self.drive_at(t);
                let (q, qd, qdd_p) = match &drive {
                    None => (q, qd, None),
                    Some(d) => {
                        put_drive(&mut self.driven, q, qd, d);
                        let (dq, dqd, qdd_p) = &self.driven;
                        (dq, dqd, Some(qdd_p))
                    }
                };
                let driven = drive.map(|d| d.coordinate);
                let key = &mut self.assembly;
                match self.axis_tree.as_mut() {
                    Some(tree) => accelerations_of_free(
                        self.model,
                        tree,
                        key,
                        q,
                        qd,
                        &self.active,
                        qdd_p,
                        driven,
                        out,
                    ),
                    None => accelerations_of_free(
                        self.model,
                        &mut self.dynamics,
                        key,
                        q,
                        qd,
                        &self.active,
                        qdd_p,
                        driven,
                        out,
                    ),
                }
            }
            _ => {
                *out = self.accelerations(t, q, qd)?;
                Ok(())
            }
        }
    }

    fn evaluation_epoch(&self) -> u64 {
        self.assembly.epoch
    }

    fn accelerations_again_into(
        &mut self,
        epoch: u64,
        t_s: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, DynamicsError> {
        self.solve_on_assembly_of(epoch, t_s, out)
    }

    fn stability_limit(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
    ) -> Option<StabilityLimit> {
        self.assembly.next_use();
        linearised_limit(self.model, &mut self.dynamics, q, qd, &self.active)
    }
}

/// `λ_max` and `β` of eq. (12) from the linearisation `M̄ δq̈ + C δq̇ + K δq = 0`, with
/// `K = −∂f̄/∂q` and `C = −∂f̄/∂q̇` by central differences. `β` is estimated conservatively as
/// `ρ(M̄⁻¹C) / (2 λ_max)`.
pub fn linearised_limit(
    model: &Model,
    dynamics: &mut Dynamics,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    active: &[bool],
) -> Option<StabilityLimit> {
    let idx: Vec<usize> = (0..q.len()).filter(|&i| active[i]).collect();
    let n = idx.len();
    if n == 0 || model.has_infinitesimal_bodies() {
        return None;
    }
    dynamics.assemble(model, q, qd, None);
    let m = dynamics.mass_matrix.select_rows(&idx).select_columns(&idx);
    let mut k = DMatrix::zeros(n, n);
    let mut c = DMatrix::zeros(n, n);
    let d = 1e-6;
    for (col, &i) in idx.iter().enumerate() {
        for (target, is_q) in [(&mut k, true), (&mut c, false)] {
            let (mut qp, mut qm, mut vp, mut vm) = (q.clone(), q.clone(), qd.clone(), qd.clone());
            if is_q {
                qp[i] += d;
                qm[i] -= d;
            } else {
                vp[i] += d;
                vm[i] -= d;
            }
            dynamics.assemble(model, &qp, &vp, None);
            let fp = dynamics.force.select_rows(&idx);
            dynamics.assemble(model, &qm, &vm, None);
            let fm = dynamics.force.select_rows(&idx);
            target.set_column(col, &((fm - fp) / (2.0 * d)));
        }
    }
    let minv = m.try_inverse()?;
    let mk = (&minv * k).complex_eigenvalues();
    let lambda2 = mk.iter().map(|z| z.norm()).fold(0.0f64, f64::max);
    let damping = (&minv * c)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    let lambda = lambda2.sqrt();
    let beta = if lambda > 0.0 {
        (damping / (2.0 * lambda)).min(1.0)
    } else {
        0.0
    };
    Some(StabilityLimit {
        lambda_max_rad_s: lambda,
        beta,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::limit_cycle::NewtonSettings;
    use crate::scene::Scene;

    /// The torque and the accelerations solved on the workspace's assembly (the cache taken
    /// both times, counted) equal, to the bit, those of a fresh phase (a fresh evaluation
    /// there: the 3D fast path's for wisse3d).
    #[test]
    fn solving_on_the_last_assembly_is_bit_for_bit_a_fresh_evaluation() {
        let setup = Scene::load("wisse3d").unwrap().setup().unwrap();
        let gait = setup.find_gait(&NewtonSettings::default()).unwrap();
        let walker = &setup.walker;
        let ankle = walker.ankle().unwrap().ankle;
        let (q, qd) = walker.unpack(&gait.fixed_point);
        let seg = |t0_s: f64, p0_rad: f64, v0_rad_s: f64, v1_rad_s: f64| ActuatorSegment {
            t0_s,
            t1_s: t0_s + 1e-3,
            p0_rad,
            v0_rad_s,
            p1_rad: p0_rad + 1e-3 * v0_rad_s,
            v1_rad_s,
            released: false,
        };
        let (old, new) = (
            seg(0.099, q[ankle.0], 0.5, 1.5),
            seg(0.1, q[ankle.0], 1.5, 3.0),
        );
        let phase_with = |s: ActuatorSegment| {
            let mut p = Phase::new(walker.model());
            p.active[ankle.0] = false;
            p.prescribed = Some((ankle, Drive::Segment(s)));
            p
        };
        let mut at = Sample {
            t_s: 0.1,
            q: q.clone(),
            qd: qd.clone(),
        };
        let mut phase = phase_with(old);
        phase.snap(&mut at);
        let mut qdd = DVector::zeros(q.len());
        phase
            .accelerations_into(0.1, &at.q, &at.qd, &mut qdd)
            .unwrap();
        // The evaluation assembled, and names its assembly by its epoch.
        let epoch = phase.evaluation_epoch();
        assert!(phase.assembly.is_of(epoch, &phase.active));
        let reuses = phase.assembly.reuses;
        let torque = phase.actuator_torque(&at, Some(epoch)).unwrap();
        // The torque was solved on the assembly, not by a fresh evaluation.
        assert_eq!(phase.assembly.reuses, reuses + 1);
        let fresh = phase_with(old).actuator_torque(&at, None).unwrap();
        assert_eq!(torque.0.to_bits(), fresh.0.to_bits());
        assert_eq!(torque.1.to_bits(), fresh.1.to_bits());
        // Another drive acceleration at the same angle and rate (the new segment's rate at its
        // start equals the old one's at its end here only in the acceleration's input): a
        // solve on the assembly, the same bits as a fresh evaluation.
        let (p_old, v_old, _) = old.eval(0.1);
        let (_, _, a_new) = new.eval(0.1);
        let other = ActuatorSegment {
            t0_s: 0.1,
            t1_s: 0.101,
            p0_rad: p_old,
            v0_rad_s: v_old,
            p1_rad: p_old + 1e-3 * v_old + 1e-7,
            v1_rad_s: v_old + 1e-3 * a_new,
            released: false,
        };
        phase.prescribed = Some((ankle, Drive::Segment(other)));
        let mut reused = DVector::zeros(q.len());
        assert!(phase
            .accelerations_again_into(epoch, 0.1, &mut reused)
            .unwrap());
        // The accelerations were solved on the assembly, not by a fresh evaluation.
        assert_eq!(phase.assembly.reuses, reuses + 2);
        let mut again = DVector::zeros(q.len());
        phase_with(other)
            .accelerations_into(0.1, &at.q, &at.qd, &mut again)
            .unwrap();
        assert!(reused
            .iter()
            .zip(again.iter())
            .all(|(a, b)| a.to_bits() == b.to_bits()));
        assert_ne!(reused, qdd);
        // After another use of the workspace, that epoch's assembly is not offered again.
        phase
            .accelerations_into(0.1, &at.q, &at.qd, &mut again)
            .unwrap();
        assert!(!phase
            .accelerations_again_into(epoch, 0.1, &mut again)
            .unwrap());
        assert!(phase.actuator_torque(&at, Some(epoch)).is_ok());
        assert_eq!(phase.assembly.reuses, reuses + 2);
    }
}
