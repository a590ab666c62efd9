//! The foot contact switch's input pin: active low as on the board (switch to ground with the
//! pin's pull-up), so a foot on the floor reads low. The firmware's
//! `firmware::drivers::contact::ContactSwitch` (`ActiveLevel::Low`) debounces it.

use std::cell::Cell;
use std::convert::Infallible;
use std::rc::Rc;

use embedded_hal::digital::{ErrorType, InputPin};

/// The pin; clones share the switch (the orchestrator keeps one to set the raw contact).
#[derive(Clone, Debug, Default)]
pub struct SimContactPin(Rc<Cell<bool>>);

impl SimContactPin {
    /// A pin with the switch open (foot in the air: pin high).
    pub fn new() -> Self {
        Self::default()
    }

    /// Set the raw (undebounced) switch: `closed` when the foot is on the floor.
    pub fn set_closed(&self, closed: bool) {
        self.0.set(closed);
    }

    /// The raw switch.
    pub fn closed(&self) -> bool {
        self.0.get()
    }
}

impl ErrorType for SimContactPin {
    type Error = Infallible;
}

impl InputPin for SimContactPin {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        Ok(!self.0.get())
    }

    fn is_low(&mut self) -> Result<bool, Infallible> {
        Ok(self.0.get())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::drivers::contact::{ActiveLevel, ContactSwitch};

    #[test]
    fn closed_switch_pulls_the_pin_low_and_the_firmware_debounces_it() {
        let line = SimContactPin::new();
        let mut pin = line.clone();
        assert!(pin.is_high().unwrap(), "open: pulled up");
        line.set_closed(true);
        assert!(pin.is_low().unwrap() && !pin.is_high().unwrap());
        let mut sw = ContactSwitch::new(line.clone(), ActiveLevel::Low, 3);
        // The firmware's switch starts from its first reading (a foot down at power-up is no
        // heel strike).
        assert_eq!(
            [sw.sample(), sw.sample(), sw.sample()],
            [Ok(true), Ok(true), Ok(true)]
        );
        line.set_closed(false);
        assert_eq!(
            [sw.sample(), sw.sample(), sw.sample()],
            [Ok(true), Ok(true), Ok(false)]
        );
        // With the wrong polarity the same wiring would read inverted.
        let mut wrong = ContactSwitch::new(line.clone(), ActiveLevel::High, 1);
        assert_eq!(wrong.sample(), Ok(true), "open switch read as closed");
    }
}
