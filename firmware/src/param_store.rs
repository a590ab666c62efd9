//! Parameters and the encoder zero in flash: a key–value map (sequential-storage, power-fail
//! safe, wear-levelled, CRC-checked) over any `embedded_storage_async` NOR flash — on the board
//! the STM32G431's own flash through embassy-stm32, in the tests a RAM flash with NOR rules.
//!
//! Keys: each [`ParamId`]'s raw value holds its wire value (i32, 1e-6 of the SI unit); key
//! [`KEY_ENCODER_ZERO`] holds the calibration (`zero_counts | reversed << 16`,
//! [`AngleCalibration::to_stored_word`]; a word with other bits set is refused). Loading
//! applies stored parameters through [`ReflexParams::set`], so a stored value outside its
//! range or inconsistent with the others is refused like a wire command would be.

use core::ops::Range;

use embedded_storage_async::nor_flash::NorFlash;
use protocol::{ConfigSource, ParamId, ParamValue};
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage};

use crate::params::ReflexParams;
use crate::sensors::AngleCalibration;

/// Key of the encoder calibration.
pub const KEY_ENCODER_ZERO: u8 = 0x80;

type NoCache = Cache<Uncached, Uncached, Uncached, u8>;

/// Why the store failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// The flash range is not a whole number of (at least two) erase pages.
    BadRange,
    /// The flash refused a read, write or erase, or its contents are corrupt beyond repair.
    Flash,
}

/// What was loaded at start-up, and from where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loaded {
    /// Parameters in force.
    pub params: ReflexParams,
    /// Where they came from.
    pub params_source: ConfigSource,
    /// Encoder calibration in force.
    pub calibration: AngleCalibration,
    /// Where it came from.
    pub calibration_source: ConfigSource,
}

/// The store over a flash range.
pub struct ParamStore<S: NorFlash> {
    map: MapStorage<u8, S, NoCache>,
}

impl<S: NorFlash> ParamStore<S> {
    /// A store in `range` of `flash` (whole erase pages, at least two).
    ///
    /// # Errors
    /// [`StoreError::BadRange`].
    pub fn new(flash: S, range: Range<u32>) -> Result<Self, StoreError> {
        let config = MapConfig::try_new(range).map_err(|_| StoreError::BadRange)?;
        Ok(ParamStore {
            map: MapStorage::new(flash, config, Cache::new_uncached()),
        })
    }

    /// Give the flash back (a simulated reset drops everything else).
    pub fn into_flash(self) -> S {
        self.map.destroy().0
    }

    /// Store every parameter's value and the calibration.
    ///
    /// # Errors
    /// [`StoreError::Flash`].
    pub async fn save(
        &mut self,
        params: &ReflexParams,
        calibration: AngleCalibration,
    ) -> Result<(), StoreError> {
        let mut buf = [0u8; 32];
        for id in ParamId::ALL {
            let v: i32 = params.wire_value(*id).0;
            self.map
                .store_item(&mut buf, &id.raw(), &v)
                .await
                .map_err(|_| StoreError::Flash)?;
        }
        let word = calibration.to_stored_word();
        self.map
            .store_item(&mut buf, &KEY_ENCODER_ZERO, &word)
            .await
            .map_err(|_| StoreError::Flash)
    }

    /// Load what is stored, falling back to `default_calibration` and the default parameters
    /// for anything missing; a flash that cannot be read gives the defaults, marked so.
    pub async fn load(&mut self, default_calibration: AngleCalibration) -> Loaded {
        let mut buf = [0u8; 32];
        let mut params = ReflexParams::default();
        let mut params_source = ConfigSource::Defaults;
        let mut stored: [Option<i32>; 16] = [None; 16];
        for id in ParamId::ALL {
            match self.map.fetch_item::<i32>(&mut buf, &id.raw()).await {
                Ok(Some(v)) => {
                    if let Some(slot) = stored.get_mut(id.raw() as usize) {
                        *slot = Some(v);
                    }
                }
                Ok(None) => {}
                Err(_) => {
                    return Loaded {
                        params: ReflexParams::default(),
                        params_source: ConfigSource::FlashUnreadable,
                        calibration: default_calibration,
                        calibration_source: ConfigSource::FlashUnreadable,
                    }
                }
            }
        }
        // Two passes: a value consistent only with another stored one (e.g. the extended
        // angle below the default taut angle) goes in on the second.
        for _ in 0..2 {
            for id in ParamId::ALL {
                if let Some(Some(v)) = stored.get(id.raw() as usize) {
                    if params.set(*id, ParamValue(*v)).is_ok() {
                        params_source = ConfigSource::Flash;
                    }
                }
            }
        }
        let (calibration, calibration_source) = match self
            .map
            .fetch_item::<u32>(&mut buf, &KEY_ENCODER_ZERO)
            .await
        {
            // A word with undefined bits is no calibration: the default, marked unreadable.
            Ok(Some(w)) => match AngleCalibration::from_stored_word(w) {
                Some(c) => (c, ConfigSource::Flash),
                None => (default_calibration, ConfigSource::FlashUnreadable),
            },
            Ok(None) => (default_calibration, ConfigSource::Defaults),
            Err(_) => (default_calibration, ConfigSource::FlashUnreadable),
        };
        Loaded {
            params,
            params_source,
            calibration,
            calibration_source,
        }
    }
}
