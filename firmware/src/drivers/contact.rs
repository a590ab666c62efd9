//! Debounced foot contact switch on a digital input.

use embedded_hal::digital::InputPin;

use crate::sensors::Debouncer;

/// Which pin level means "foot on the floor".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActiveLevel {
    /// Closed switch pulls the pin high.
    High,
    /// Closed switch pulls the pin low (pull-up, switch to ground).
    Low,
}

/// A contact switch sampled once per tick and debounced.
pub struct ContactSwitch<P> {
    pin: P,
    level: ActiveLevel,
    samples: u8,
    debouncer: Option<Debouncer>,
}

impl<P: InputPin> ContactSwitch<P> {
    /// Debounce over `samples` consecutive ticks (3 at 1 kHz: 3 ms). The debounced state
    /// starts from the first reading (a foot already on the floor at power-up is no heel
    /// strike); until then it reads open.
    pub fn new(pin: P, level: ActiveLevel, samples: u8) -> Self {
        ContactSwitch {
            pin,
            level,
            samples,
            debouncer: None,
        }
    }

    /// Sample the pin; returns the debounced state (true: foot on the floor).
    ///
    /// # Errors
    /// The pin's error; the debounced state is unchanged then.
    pub fn sample(&mut self) -> Result<bool, P::Error> {
        let high = self.pin.is_high()?;
        let closed = match self.level {
            ActiveLevel::High => high,
            ActiveLevel::Low => !high,
        };
        let samples = self.samples;
        Ok(self
            .debouncer
            .get_or_insert_with(|| Debouncer::new(closed, samples))
            .update(closed))
    }

    /// The debounced state (open before the first reading).
    pub fn closed(&self) -> bool {
        self.debouncer.is_some_and(|d| d.state())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::convert::Infallible;
    use embedded_hal::digital::ErrorType;

    struct Pin<'a>(&'a [bool], usize);
    impl ErrorType for Pin<'_> {
        type Error = Infallible;
    }
    impl InputPin for Pin<'_> {
        fn is_high(&mut self) -> Result<bool, Infallible> {
            let v = self.0[self.1];
            self.1 += 1;
            Ok(v)
        }
        fn is_low(&mut self) -> Result<bool, Infallible> {
            self.is_high().map(|h| !h)
        }
    }

    #[test]
    fn active_low_switch_is_debounced() {
        let levels = [true, false, true, false, false, false, true];
        let mut c = ContactSwitch::new(Pin(&levels, 0), ActiveLevel::Low, 3);
        assert!(!c.closed(), "open before the first reading");
        let got: [bool; 7] = core::array::from_fn(|_| c.sample().unwrap());
        assert_eq!(got, [false, false, false, false, false, true, true]);
        assert!(c.closed());
    }

    #[test]
    fn a_foot_down_at_power_up_reads_closed_from_the_first_sample() {
        let levels = [false, false, true, false];
        let mut c = ContactSwitch::new(Pin(&levels, 0), ActiveLevel::Low, 3);
        let got: [bool; 4] = core::array::from_fn(|_| c.sample().unwrap());
        assert_eq!(
            got,
            [true, true, true, true],
            "no open-to-closed edge at boot"
        );
    }
}
