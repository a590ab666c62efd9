//! Parameters and encoder zero survive a simulated reset through the flash store: saved by
//! one `ParamStore`, the store dropped (all RAM state gone), a new store over the same flash
//! bytes loads them. The flash is a RAM model with NOR rules (erase to 0xFF by page, aligned
//! writes of whole double words, only over erased ones: a write over a programmed word is
//! refused, as the G431 refuses it with PROGERR), the STM32G431's geometry (2 KiB pages,
//! 8-byte double words). Also: garbage in the range, a corrupted bit in a stored map, stored
//! values out of range.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use embassy_futures::block_on;
use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use firmware::param_store::{ParamStore, StoreError};
use firmware::params::ReflexParams;
use firmware::sensors::AngleCalibration;
use protocol::{ConfigSource, ParamId, ParamValue};
use sequential_storage::cache::Cache;
use sequential_storage::map::{MapConfig, MapStorage};

const PAGE: usize = 2048;
const PAGES: usize = 4;

struct RamNor {
    bytes: Vec<u8>,
    writes: usize,
    /// Erases of each page.
    erases: [usize; PAGES],
    /// Writes refused because they would program a word that is not erased.
    refused_writes: usize,
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
            erases: [0; PAGES],
            refused_writes: 0,
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
        for page in f / PAGE..t / PAGE {
            self.erases[page] += 1;
        }
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
        // The STM32G4 programs whole double words, only over erased ones: a write over a
        // programmed one is refused (PROGERR), and so is the rest of the write. The tests that
        // save `unwrap` the result, so the store doing so in normal use fails them.
        let dst = &mut self.bytes[o..o + bytes.len()];
        if dst.iter().any(|b| *b != 0xFF) {
            self.refused_writes += 1;
            return Err(NorError(NorFlashErrorKind::Other));
        }
        dst.copy_from_slice(bytes);
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
    // Saving again (newer values win) and many times over: 200 saves of about 130 bytes each
    // are about three times the 8 KiB range, so the map wraps over its pages, erasing each
    // (measured: every page erased 2 or 3 times; the first erase at the 60th save).
    let mut p2 = params;
    p2.set(ParamId::PushDuration, ParamValue(100_000)).unwrap();
    for _ in 0..200 {
        block_on(store.save(&p2, cal)).unwrap();
    }
    let flash = store.into_flash();
    eprintln!("erases per page after 201 saves: {:?}", flash.erases);
    assert!(flash.erases.iter().all(|&e| e >= 2), "{:?}", flash.erases);
    assert_eq!(flash.refused_writes, 0);
    let mut store = ParamStore::new(flash, RANGE).unwrap();
    let loaded = block_on(store.load(DEFAULT_CAL));
    assert_eq!(loaded.params, p2);
    assert_eq!(loaded.params_source, ConfigSource::Flash);
    assert_eq!(loaded.calibration, cal);
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

/// Every parameter of `loaded` within its range.
fn assert_in_range(params: &ReflexParams) {
    for id in ParamId::ALL {
        let (lo, hi) = id.range_si();
        let v = params.wire_value(*id).0 as f32 * 1e-6;
        assert!(v >= lo - 1e-6 && v <= hi + 1e-6, "{id:?} = {v}");
    }
}

#[test]
fn garbage_in_flash_never_yields_out_of_range_parameters() {
    // A flash full of a non-erased pattern (what a range that held something else, e.g. an
    // older, larger firmware image, looks like): the store finds no record in it and gives the
    // defaults, marked `Defaults`. A save there erases one page, then finds the next word it
    // would program not erased: the flash refuses the write and the save fails, this time and
    // every time after (present behaviour: the store has no way back but an erase of its
    // range from outside). Nothing out of range is ever in force.
    let mut flash = RamNor::erased();
    for (k, b) in flash.bytes.iter_mut().enumerate() {
        *b = (k * 31 % 251) as u8;
    }
    let mut store = ParamStore::new(flash, RANGE).unwrap();
    let loaded = block_on(store.load(DEFAULT_CAL));
    assert_in_range(&loaded.params);
    assert_eq!(loaded.params, ReflexParams::default());
    assert_eq!(loaded.params_source, ConfigSource::Defaults);
    assert_eq!(loaded.calibration_source, ConfigSource::Defaults);
    for attempt in 1..=3 {
        assert_eq!(
            block_on(store.save(&changed_params(), DEFAULT_CAL)),
            Err(StoreError::Flash),
            "save {attempt} over garbage"
        );
        let flash = store.into_flash();
        assert_eq!((flash.writes, flash.refused_writes), (0, attempt));
        store = ParamStore::new(flash, RANGE).unwrap();
        let loaded = block_on(store.load(DEFAULT_CAL));
        assert_in_range(&loaded.params);
        assert_eq!(loaded.params_source, ConfigSource::Defaults);
    }
    // Erased (as the board's programmer would), the same range stores and loads again.
    let mut flash = store.into_flash();
    block_on(flash.erase(RANGE.start, RANGE.end)).unwrap();
    let mut store = ParamStore::new(flash, RANGE).unwrap();
    block_on(store.save(&changed_params(), DEFAULT_CAL)).unwrap();
    assert_eq!(block_on(store.load(DEFAULT_CAL)).params, changed_params());
}

#[test]
fn a_corrupted_bit_in_a_stored_map_gives_saved_values_or_defaults_never_others() {
    // Every bit of what one save programmed, flipped one at a time: the records' CRCs and the
    // pages' markers catch the flip, and each parameter loads as the value saved or as its
    // default, never as a third value; a flip in one record leaves the others loaded from
    // flash.
    let params = changed_params();
    let cal = AngleCalibration {
        zero_counts: 12_345,
        reversed: true,
    };
    let mut store = ParamStore::new(RamNor::erased(), RANGE).unwrap();
    block_on(store.save(&params, cal)).unwrap();
    let saved = store.into_flash().bytes;
    let programmed: Vec<usize> = (0..saved.len()).filter(|&k| saved[k] != 0xFF).collect();
    let defaults = ReflexParams::default();
    let (mut all_saved, mut some_defaults, mut all_defaults) = (0, 0, 0);
    for &k in &programmed {
        for bit in 0..8 {
            let mut flash = RamNor::erased();
            flash.bytes.copy_from_slice(&saved);
            flash.bytes[k] ^= 1 << bit;
            let mut store = ParamStore::new(flash, RANGE).unwrap();
            let loaded = block_on(store.load(DEFAULT_CAL));
            assert_in_range(&loaded.params);
            let mut from_flash = 0;
            for id in ParamId::ALL {
                let v = loaded.params.wire_value(*id);
                assert!(
                    v == params.wire_value(*id) || v == defaults.wire_value(*id),
                    "byte {k} bit {bit}: {id:?} = {v:?}"
                );
                from_flash +=
                    usize::from(v == params.wire_value(*id) && v != defaults.wire_value(*id));
            }
            assert!(
                loaded.calibration == cal || loaded.calibration == DEFAULT_CAL,
                "byte {k} bit {bit}: {:?}",
                loaded.calibration
            );
            match from_flash {
                3 => all_saved += 1,
                0 => all_defaults += 1,
                _ => some_defaults += 1,
            }
        }
    }
    eprintln!(
        "{} bits flipped in {} programmed bytes: all three changed values loaded {all_saved}, some {some_defaults}, none {all_defaults}",
        8 * programmed.len(),
        programmed.len()
    );
    // A flip in one record loses that record only.
    assert!(some_defaults > 0, "no flip lost a single record");
}

#[test]
fn stored_values_out_of_range_are_refused_one_by_one() {
    // Records that are whole (their CRCs right) but hold values a wire command would be
    // refused: written through the same map, then loaded. Each bad value is refused
    // (`ReflexParams::set`), its parameter keeps the default, and the good ones load.
    let mut map = MapStorage::<u8, _, _>::new(
        RamNor::erased(),
        MapConfig::try_new(RANGE).unwrap(),
        Cache::new_uncached(),
    );
    let mut buf = [0u8; 32];
    let records: [(ParamId, i32); 3] = [
        (ParamId::PushDuration, 200_000),   // 0.2 s: in range
        (ParamId::StuckTimeout, i32::MAX),  // 2147 s: far above 1 s
        (ParamId::ExtendedAngle, -900_000), // −0.9 rad: below its range, [0, 0.4]
    ];
    for (id, v) in records {
        block_on(map.store_item(&mut buf, &id.raw(), &v)).unwrap();
    }
    let mut store = ParamStore::new(map.destroy().0, RANGE).unwrap();
    let loaded = block_on(store.load(DEFAULT_CAL));
    assert_eq!(loaded.params_source, ConfigSource::Flash);
    assert_in_range(&loaded.params);
    let defaults = ReflexParams::default();
    assert_eq!(
        loaded.params.wire_value(ParamId::PushDuration),
        ParamValue(200_000)
    );
    for id in [ParamId::StuckTimeout, ParamId::ExtendedAngle] {
        assert_eq!(
            loaded.params.wire_value(id),
            defaults.wire_value(id),
            "{id:?}"
        );
    }
}
