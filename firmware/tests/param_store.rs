//! Parameters and encoder zero survive a simulated reset through the flash store: saved by
//! one `ParamStore`, the store dropped (all RAM state gone), a new store over the same flash
//! bytes loads them. The flash is a RAM model with NOR rules (erase to 0xFF by page, a write
//! may only clear bits of an erased word, aligned words), the STM32G431's geometry (2 KiB
//! pages, 8-byte double words).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use embassy_futures::block_on;
use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use firmware::param_store::{ParamStore, StoreError};
use firmware::params::ReflexParams;
use firmware::sensors::AngleCalibration;
use protocol::{ConfigSource, ParamId, ParamValue};

const PAGE: usize = 2048;
const PAGES: usize = 4;

struct RamNor {
    bytes: Vec<u8>,
    writes: usize,
}

#[derive(Debug)]
struct NorError(NorFlashErrorKind);
impl NorFlashError for NorError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

impl RamNor {
    fn erased() -> Self {
        RamNor {
            bytes: vec![0xFF; PAGE * PAGES],
            writes: 0,
        }
    }
}

impl ErrorType for RamNor {
    type Error = NorError;
}

impl ReadNorFlash for RamNor {
    const READ_SIZE: usize = 1;
    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), NorError> {
        let o = offset as usize;
        let src = self
            .bytes
            .get(o..o + bytes.len())
            .ok_or(NorError(NorFlashErrorKind::OutOfBounds))?;
        bytes.copy_from_slice(src);
        Ok(())
    }
    fn capacity(&self) -> usize {
        self.bytes.len()
    }
}

impl NorFlash for RamNor {
    const WRITE_SIZE: usize = 8;
    const ERASE_SIZE: usize = PAGE;
    async fn erase(&mut self, from: u32, to: u32) -> Result<(), NorError> {
        let (f, t) = (from as usize, to as usize);
        if !f.is_multiple_of(PAGE) || !t.is_multiple_of(PAGE) || t > self.bytes.len() {
            return Err(NorError(NorFlashErrorKind::NotAligned));
        }
        self.bytes[f..t].fill(0xFF);
        Ok(())
    }
    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), NorError> {
        let o = offset as usize;
        if !o.is_multiple_of(8)
            || !bytes.len().is_multiple_of(8)
            || o + bytes.len() > self.bytes.len()
        {
            return Err(NorError(NorFlashErrorKind::NotAligned));
        }
        // The STM32G4 programs whole double words, only over erased ones.
        for (k, chunk) in bytes.chunks(8).enumerate() {
            let dst = &mut self.bytes[o + 8 * k..o + 8 * k + 8];
            assert!(
                dst.iter().all(|b| *b == 0xFF),
                "write over a programmed word"
            );
            dst.copy_from_slice(chunk);
        }
        self.writes += 1;
        Ok(())
    }
}

const RANGE: core::ops::Range<u32> = 0..(PAGE * PAGES) as u32;
const DEFAULT_CAL: AngleCalibration = AngleCalibration {
    zero_counts: 0,
    reversed: false,
};

fn changed_params() -> ReflexParams {
    let mut p = ReflexParams::default();
    // Extended angle 0.3 rad, push 0.2 s, stuck timeout 40 ms.
    p.set(ParamId::ExtendedAngle, ParamValue(300_000)).unwrap();
    p.set(ParamId::PushDuration, ParamValue(200_000)).unwrap();
    p.set(ParamId::StuckTimeout, ParamValue(40_000)).unwrap();
    p
}

#[test]
fn parameters_and_encoder_zero_survive_a_simulated_reset() {
    let params = changed_params();
    let cal = AngleCalibration {
        zero_counts: 12_345,
        reversed: true,
    };
    let mut store = ParamStore::new(RamNor::erased(), RANGE).unwrap();
    block_on(store.save(&params, cal)).unwrap();
    // Reset: every RAM structure gone, only the flash bytes stay.
    let flash = store.into_flash();
    assert!(flash.writes > 0);
    let mut store = ParamStore::new(flash, RANGE).unwrap();
    let loaded = block_on(store.load(DEFAULT_CAL));
    assert_eq!(loaded.params, params);
    assert_eq!(loaded.params_source, ConfigSource::Flash);
    assert_eq!(loaded.calibration, cal);
    assert_eq!(loaded.calibration_source, ConfigSource::Flash);
    // Saving again (newer values win) and many times over (the map wraps over its pages).
    let mut p2 = params;
    p2.set(ParamId::PushDuration, ParamValue(100_000)).unwrap();
    for _ in 0..200 {
        block_on(store.save(&p2, cal)).unwrap();
    }
    let mut store = ParamStore::new(store.into_flash(), RANGE).unwrap();
    assert_eq!(block_on(store.load(DEFAULT_CAL)).params, p2);
}

#[test]
fn an_empty_flash_gives_the_defaults_and_a_bad_range_is_refused() {
    let mut store = ParamStore::new(RamNor::erased(), RANGE).unwrap();
    let loaded = block_on(store.load(DEFAULT_CAL));
    assert_eq!(loaded.params, ReflexParams::default());
    assert_eq!(loaded.params_source, ConfigSource::Defaults);
    assert_eq!(loaded.calibration, DEFAULT_CAL);
    assert_eq!(loaded.calibration_source, ConfigSource::Defaults);
    assert!(matches!(
        ParamStore::new(RamNor::erased(), 0..PAGE as u32),
        Err(StoreError::BadRange)
    ));
    assert!(matches!(
        ParamStore::new(RamNor::erased(), 100..(4 * PAGE) as u32),
        Err(StoreError::BadRange)
    ));
}

#[test]
fn garbage_in_flash_never_yields_out_of_range_parameters() {
    // A flash full of a non-erased pattern: whatever the store makes of it, the parameters
    // in force are valid ones (loaded through ReflexParams::set) or the defaults.
    let mut flash = RamNor::erased();
    for (k, b) in flash.bytes.iter_mut().enumerate() {
        *b = (k * 31 % 251) as u8;
    }
    let mut store = ParamStore::new(flash, RANGE).unwrap();
    let loaded = block_on(store.load(DEFAULT_CAL));
    for id in ParamId::ALL {
        let (lo, hi) = id.range_si();
        let v = loaded.params.wire_value(*id).0 as f32 * 1e-6;
        assert!(v >= lo - 1e-6 && v <= hi + 1e-6, "{id:?} = {v}");
    }
}
