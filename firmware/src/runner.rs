//! The hardware-generic driver layer: one [`AnkleDrivers::step`] per control tick reads the
//! encoder and the contact switch, drains the CAN receive queue, ticks the [`AnkleNode`],
//! applies the actuator command and queues the node's messages.

use embedded_can::nb::Can;
use embedded_hal::digital::InputPin;
use heapless::Vec;

use crate::bench_log::BenchEvent;
use crate::drivers::actuator::Actuator;
use crate::drivers::can::{BusState, CanPort, ControllerHealth};
use crate::drivers::contact::ContactSwitch;
use crate::drivers::encoder::AngleSensor;
use crate::node::{AnkleNode, DriverHealth, NodeRequest, TickInputs, TickOutputs, MAX_RX_PER_TICK};
use crate::time::Monotonic;
use protocol::NodeState;

/// Every driver of one ankle, and its node.
pub struct AnkleDrivers<E, P, A, C, M> {
    /// The node logic.
    pub node: AnkleNode,
    /// Ankle angle encoder (SPI, or PWM output on the board).
    pub encoder: E,
    /// Foot contact switch.
    pub contact: ContactSwitch<P>,
    /// String actuator.
    pub actuator: A,
    /// CAN port.
    pub can: CanPort<C>,
    /// Clock.
    pub clock: M,
    health: DriverHealth,
}

impl<E, P, A, C, M> AnkleDrivers<E, P, A, C, M>
where
    E: AngleSensor,
    P: InputPin,
    A: Actuator,
    C: Can + ControllerHealth,
    M: Monotonic,
{
    /// Assemble the drivers.
    pub fn new(
        node: AnkleNode,
        encoder: E,
        contact: ContactSwitch<P>,
        actuator: A,
        can: CanPort<C>,
        clock: M,
    ) -> Self {
        AnkleDrivers {
            node,
            encoder,
            contact,
            actuator,
            can,
            clock,
            health: DriverHealth::default(),
        }
    }

    /// One control tick. Bounded: one encoder read, one pin read, at most
    /// 2 × [`MAX_RX_PER_TICK`] frame reads and a bounded number of frame writes.
    pub fn step(&mut self) -> TickOutputs {
        let now = self.clock.now();
        let angle = self.encoder.read_angle();
        // A pin error keeps the last debounced state; contact pins on MCUs are infallible.
        let contact_closed = self
            .contact
            .sample()
            .unwrap_or_else(|_| self.contact.closed());
        let mut received: Vec<_, MAX_RX_PER_TICK> = Vec::new();
        self.can.receive(&mut received);
        let before = self.can.stats();
        let lost_before = before.rx_lost;
        let bus = self.can.poll_status();
        if bus != before.status.state {
            let st = self.can.stats().status;
            self.node.log_event(
                now,
                BenchEvent::CanState {
                    from: before.status.state,
                    to: bus,
                    tec: st.tx_errors,
                    rec: st.rx_errors,
                },
            );
        }
        let rx_lost = self.can.stats().rx_lost.wrapping_sub(lost_before);
        let inputs = TickInputs {
            angle,
            contact_closed,
            received: &received,
            drivers: DriverHealth {
                can_bus_off: bus == BusState::BusOff,
                rx_lost,
                ..self.health
            },
        };
        let out = self.node.tick(now, &inputs);
        // An encoder-zero calibration takes effect at once; a save is the caller's (it needs
        // the flash), reported back with `AnkleNode::storage_done`.
        if let Some(NodeRequest::SetEncoderZero { zero_counts }) = out.request {
            self.encoder.set_zero_counts(zero_counts);
        }
        let measured = self.node.estimate().map(|(a, _)| a);
        // Emergency stop: the actuator off at once (no pay-out sequence).
        let result = if out.state == NodeState::EmergencyStop {
            self.actuator.stop()
        } else {
            self.actuator.apply(out.actuator, measured)
        };
        self.health.actuator_error = result.is_err();
        self.health.actuator_error_detail = result.err().map_or(0, |e| e.detail());
        self.health.string_moving = self.actuator.string_moving();
        self.health.spool_sensor = self.actuator.has_spool_sensor();
        self.health.can_error = self.can.transmit(&out.transmit);
        out
    }
}
