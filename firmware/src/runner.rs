//! The hardware-generic driver layer: one [`AnkleDrivers::step`] per control tick reads the
//! encoder and the contact switch, drains the CAN receive queue, ticks the [`AnkleNode`],
//! applies the actuator command and queues the node's messages.

use embedded_can::nb::Can;
use embedded_hal::digital::InputPin;
use embedded_hal::spi::SpiDevice;
use heapless::Vec;

use crate::drivers::actuator::Actuator;
use crate::drivers::can::CanPort;
use crate::drivers::contact::ContactSwitch;
use crate::drivers::encoder::MagneticEncoder;
use crate::node::{AnkleNode, DriverHealth, TickInputs, TickOutputs, MAX_RX_PER_TICK};
use crate::time::Monotonic;

/// Every driver of one ankle, and its node.
pub struct AnkleDrivers<S, P, A, C, M> {
    /// The node logic.
    pub node: AnkleNode,
    /// Angle encoder.
    pub encoder: MagneticEncoder<S>,
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

impl<S, P, A, C, M> AnkleDrivers<S, P, A, C, M>
where
    S: SpiDevice,
    P: InputPin,
    A: Actuator,
    C: Can,
    M: Monotonic,
{
    /// Assemble the drivers.
    pub fn new(
        node: AnkleNode,
        encoder: MagneticEncoder<S>,
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

    /// One control tick. Bounded: two SPI words, one pin read, at most
    /// 2 × [`MAX_RX_PER_TICK`] frame reads and a bounded number of frame writes.
    pub fn step(&mut self) -> TickOutputs {
        let now = self.clock.now();
        let angle = self.encoder.read();
        // A pin error keeps the last debounced state; contact pins on MCUs are infallible.
        let contact_closed = self
            .contact
            .sample()
            .unwrap_or_else(|_| self.contact.closed());
        let mut received: Vec<_, MAX_RX_PER_TICK> = Vec::new();
        let rx_error = self.can.receive(&mut received);
        let inputs = TickInputs {
            angle,
            contact_closed,
            received: &received,
            drivers: DriverHealth {
                can_error: self.health.can_error || rx_error,
                ..self.health
            },
        };
        let out = self.node.tick(now, &inputs);
        let measured = self.node.estimate().map(|(a, _)| a);
        self.health.actuator_error = self.actuator.apply(out.actuator, measured).is_err();
        self.health.can_error = self.can.transmit(&out.transmit);
        out
    }
}
