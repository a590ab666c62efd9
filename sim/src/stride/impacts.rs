//! Every impact of a stride, in one place: the coordinate-locking impact (a knee reaching its
//! stop, the stance heel landing flat), the string's engagement on the stance ankle, and the
//! heel-strike impact with its lift check and relabelling that end the stride.
//!
//! All are inelastic impacts (eq. 21 with restitution 0, or eq. 20 for heel strike) solved by
//! [`crate::engine::impact`]; each reports the mechanical energy it dissipates and the work a drive
//! holding the ankle does through it.

use super::contact_figures::ContactSummary;
use super::energy::energy;
use super::failure::{FailureCause, StrideFailure};
use super::phase::Drive;
use super::result::{StrideEvent, StrideResult};
use crate::engine::actuator::AnkleReflex;
use crate::engine::dynamics::Dynamics;
use crate::engine::hybrid::contact_rows::{heel_strike_rows, HeelStrikeRows};
use crate::engine::hybrid::impact::{locked_state, unit_row};
use crate::engine::impact::{resolve, resolve_to, ImpactError};
use crate::engine::integrators::Sample;
use crate::engine::kinematics::Kinematics;
use crate::engine::model::CoordIndex;
use crate::engine::relabel::LinkStates;
use crate::engine::walker::Walker;
use nalgebra::{DVector, Vector3};

/// The heel-strike impact on the impact model (coordinates: released root first).
#[derive(Clone, Debug)]
pub struct HeelStrikeImpact {
    /// Coordinates of the impact model.
    pub q: DVector<f64>,
    /// Velocities before.
    pub qd_minus: DVector<f64>,
    /// Velocities after.
    pub qd_plus: DVector<f64>,
    /// Contact impulse per constraint row.
    pub impulse: DVector<f64>,
    /// The new contact point in the stance frame \[m\].
    pub p_contact_m: Vector3<f64>,
    /// Mechanical energy lost \[J\].
    pub energy_loss_j: f64,
}

/// The outcome of [`Walker::lock_coordinate`].
pub(super) struct Locked {
    /// The state after the impact.
    pub(super) after: Sample,
    /// Mechanical energy dissipated [J] (the drive's work included).
    pub(super) loss_j: f64,
    /// Work of a drive holding the ankle through the impact [J].
    pub(super) drive_work_j: f64,
}

/// The outcome of [`Walker::engage_string`].
pub(super) struct Engaged {
    /// The state after the impact: the ankle on the drive, the foot pivoting about its toe.
    pub(super) after: Sample,
    /// The free coordinates after the impact (the toe pitch freed, the ankle driven).
    pub(super) active: Vec<bool>,
    /// Work of the drive's far end on the string's impulse [J] (zero for the ideal drive,
    /// which starts at rest).
    pub(super) drive_work_j: f64,
    /// Mechanical energy the impact dissipates, apart from the drive's work [J].
    pub(super) dissipated_j: f64,
}

impl Walker {
    /// An inelastic impact that locks coordinate `c` at `value` (a knee at its stop, a foot
    /// landing flat), the other free coordinates `active`, a coordinate driven as `prescribed`.
    pub(super) fn lock_coordinate(
        &self,
        (active, prescribed): (&[bool], Option<(CoordIndex, Drive)>),
        at: &Sample,
        c: usize,
        value: f64,
    ) -> Result<Locked, StrideFailure> {
        let g = unit_row(self.model().dof(), c);
        let mut dynamics = Dynamics::new(self.model());
        let before = energy(&mut dynamics, self.model(), at);
        let imp = resolve(&mut dynamics, self.model(), &at.q, &at.qd, active, &g, 0.0)
            .map_err(|e| StrideFailure::new(at.t_s, e))?;
        // A drive holding the ankle through the impact takes an impulse and does work on it
        // (impulse × its rate, which the impact does not change): the actuator's work, not part
        // of the impact's loss.
        let drive_work_j = match prescribed {
            Some((a, _)) => {
                let dqd = &imp.qd_plus - &at.qd;
                (dynamics.mass_matrix.row(a.0) * dqd)[(0, 0)] * at.qd[a.0]
            }
            None => 0.0,
        };
        let (q, qd) = locked_state(&at.q, imp.qd_plus, c, value, 0.0);
        let after = Sample { t_s: at.t_s, q, qd };
        let loss_j = before - energy(&mut dynamics, self.model(), &after) + drive_work_j;
        Ok(Locked {
            after,
            loss_j,
            drive_work_j,
        })
    }

    /// The string becomes taut at `at`: an inelastic impact stops the ankle (moving it on
    /// with the drive's rate) while the foot becomes free to pivot about its toe. The string's
    /// far end moves along `drive` (fixed for the ideal reflex, with the actuator under a
    /// controller).
    pub(super) fn engage_string(
        &self,
        active: &[bool],
        at: &Sample,
        reflex: &AnkleReflex,
        drive: &Drive,
    ) -> Result<Engaged, StrideFailure> {
        let (a, toe) = (reflex.ankle.0, reflex.toe_pitch.0);
        let mut act = active.to_vec();
        act[toe] = true;
        let g = unit_row(self.model().dof(), a);
        let (p_rad, v_rad_s, _) = drive.eval(at.t_s);
        let mut dynamics = Dynamics::new(self.model());
        let before = energy(&mut dynamics, self.model(), at);
        let target = DVector::from_element(1, v_rad_s);
        let imp = resolve_to(
            &mut dynamics,
            self.model(),
            &at.q,
            &at.qd,
            &act,
            &g,
            &target,
        )
        .map_err(|e| StrideFailure::new(at.t_s, e))?;
        // The string's impulse on the ankle, with its far end moving at the drive's rate, is
        // work the actuator does (zero for the ideal drive, which starts at rest).
        let drive_work_j = imp.impulse[0] * v_rad_s;
        let (q, qd) = locked_state(&at.q, imp.qd_plus, a, p_rad, v_rad_s);
        if qd[toe] > 0.0 {
            return Err(StrideFailure::new(
                at.t_s,
                FailureCause::HeelMovesDown {
                    toe_pitch_rate_rad_s: qd[toe],
                },
            ));
        }
        let after = Sample { t_s: at.t_s, q, qd };
        let dissipated_j = before - energy(&mut dynamics, self.model(), &after);
        act[a] = false;
        Ok(Engaged {
            after,
            active: act,
            drive_work_j,
            dissipated_j,
        })
    }

    /// The heel-strike impact at `at` (stance labelling) with the stance contact released:
    /// eq. (21) on the impact model. Does not check the lift or relabel.
    pub fn heel_strike_impact(
        &self,
        at: &Sample,
        active: &[bool],
    ) -> Result<HeelStrikeImpact, ImpactError> {
        let hs = &self.heel_strike();
        let m = &self.impact_model();
        let HeelStrikeRows {
            q,
            qd,
            active: act,
            g,
            p_contact_m: p_foot,
        } = heel_strike_rows(m, hs, &at.q, &at.qd, active);
        let mut dynamics = Dynamics::new(m);
        let before = energy(
            &mut dynamics,
            m,
            &Sample {
                t_s: at.t_s,
                q: q.clone(),
                qd: qd.clone(),
            },
        );
        let imp = resolve(&mut dynamics, m, &q, &qd, &act, &g, hs.restitution)?;
        let after = energy(
            &mut dynamics,
            m,
            &Sample {
                t_s: at.t_s,
                q: q.clone(),
                qd: imp.qd_plus.clone(),
            },
        );
        Ok(HeelStrikeImpact {
            q,
            qd_minus: qd,
            qd_plus: imp.qd_plus,
            impulse: imp.impulse,
            p_contact_m: p_foot,
            energy_loss_j: before - after,
        })
    }

    /// Heel-strike impact, lift check, relabelling: the end of the stride. The run's own
    /// figures (work, dissipation, evaluations, event states, contact) are left for the caller.
    pub(super) fn finish_stride(
        &self,
        at: Sample,
        active: &[bool],
        events: Vec<StrideEvent>,
        mut energy_loss: f64,
    ) -> Result<StrideResult, StrideFailure> {
        let t = at.t_s;
        let hs = &self.heel_strike();
        let nr = hs.release.len();
        let m = &self.impact_model();
        let HeelStrikeImpact {
            q,
            qd_plus,
            p_contact_m: p_foot,
            energy_loss_j,
            ..
        } = self
            .heel_strike_impact(&at, active)
            .map_err(|e| StrideFailure::new(t, e))?;
        energy_loss += energy_loss_j;
        let mut kin = Kinematics::new(m);
        kin.update(m, &q, &qd_plus);
        let sc = &m.points[hs.stance_contact.0];
        let p_sc = kin.position_of(sc.link, &sc.p_link_m);
        let lift = kin.velocity_of(sc.link, &p_sc).y;
        if lift <= 0.0 {
            return Err(StrideFailure::new(
                t,
                FailureCause::StanceFootDidNotLift { lift_m_s: lift },
            ));
        }
        let states = LinkStates::from_kinematics(&kin, nr, &p_foot);
        let solved = self
            .relabel()
            .solve(self.model(), &states, self.relabel_reference_q())
            .or_else(|_| self.relabel().solve(self.model(), &states, &at.q))
            .map_err(|e| StrideFailure::new(t, e))?;
        Ok(StrideResult {
            q_next: solved.q,
            qd_next: solved.qd,
            duration_s: t,
            step_m: p_foot,
            heading_change_rad: solved.cyclic_values.first().copied().unwrap_or(0.0),
            events,
            pre_impact: at,
            lift_velocity_m_s: lift,
            impact_energy_loss_j: energy_loss,
            evaluations: 0,
            trajectory: Vec::new(),
            event_states: Vec::new(),
            actuator_work_j: 0.0,
            damping_dissipation_j: 0.0,
            contact: ContactSummary::default(),
        })
    }
}
