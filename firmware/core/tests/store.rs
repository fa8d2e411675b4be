//! The configuration log over two flash regions in RAM that behave like NOR flash: writes can
//! only clear bits, erasing sets them all, and power can be cut at any step of a save.

use std::cell::Cell;
use std::rc::Rc;

use pen_core::default_config;
use pen_core::store::{ConfigStore, FlashRegion, LAYOUT, LogStore, RECORD_LEN, Saved, StoreError};
use pen_protocol::{CRC, Config, Report};

/// Steps of flash work left before the power goes; `None`: no cut. Shared by both regions, as
/// one supply feeds the chip.
type Power = Rc<Cell<Option<usize>>>;

struct RamFlash {
    bytes: Vec<u8>,
    erases: usize,
    power: Power,
}

impl RamFlash {
    fn new(records: usize, power: &Power) -> RamFlash {
        RamFlash {
            bytes: vec![0xFF; records * RECORD_LEN + 7],
            erases: 0,
            power: power.clone(),
        }
    }

    /// Takes one step of power; false once the power is gone.
    fn step(&self) -> bool {
        match self.power.get() {
            None => true,
            Some(0) => false,
            Some(n) => {
                self.power.set(Some(n - 1));
                true
            }
        }
    }
}

fn pair(records: usize, power: &Power) -> [RamFlash; 2] {
    [RamFlash::new(records, power), RamFlash::new(records, power)]
}

impl FlashRegion for RamFlash {
    fn size(&self) -> usize {
        self.bytes.len()
    }
    fn read(&mut self, offset: usize, buf: &mut [u8]) -> Result<(), StoreError> {
        buf.copy_from_slice(self.bytes.get(offset..offset + buf.len()).ok_or(StoreError::Flash)?);
        Ok(())
    }
    /// One step per 4-byte word, as the STM32F4 programs at 32-bit parallelism.
    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), StoreError> {
        assert!(
            offset.is_multiple_of(4) && bytes.len().is_multiple_of(4),
            "4-byte writes"
        );
        let dst = self.bytes.get(offset..offset + bytes.len()).ok_or(StoreError::Flash)?;
        assert!(dst.iter().all(|&b| b == 0xFF), "writes go to erased flash only");
        for (k, word) in bytes.chunks(4).enumerate() {
            if !self.step() {
                return Err(StoreError::Flash);
            }
            for (i, &b) in word.iter().enumerate() {
                // NOR flash: programming only clears bits.
                self.bytes[offset + 4 * k + i] &= b;
            }
        }
        Ok(())
    }
    /// Two steps: an erase cut after the first leaves half the region erased and the rest
    /// with bits cleared at random-looking places, as a cut erase does.
    fn erase(&mut self) -> Result<(), StoreError> {
        if !self.step() {
            return Err(StoreError::Flash);
        }
        let half = self.bytes.len() / 2;
        self.bytes[..half].iter_mut().for_each(|b| *b = 0xFF);
        if !self.step() {
            for (i, b) in self.bytes[half..].iter_mut().enumerate() {
                *b &= (i as u8).wrapping_mul(151) | 0x0F;
            }
            return Err(StoreError::Flash);
        }
        self.bytes.iter_mut().for_each(|b| *b = 0xFF);
        self.erases += 1;
        Ok(())
    }
}

/// The default configuration at `temperature_c`, saved with the head off.
fn config(temperature_c: f32) -> Saved {
    Saved::config(Config {
        temperature_c,
        ..default_config()
    })
}

#[test]
fn empty_flash_has_no_configuration() {
    let power = Power::default();
    assert_eq!(LogStore::new(pair(4, &power)).load(), None);
}

#[test]
fn the_newest_save_loads_and_the_regions_take_turns() {
    let power = Power::default();
    let mut store = LogStore::new(pair(3, &power));
    for (i, t) in [10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0, 18.0, 19.0]
        .into_iter()
        .enumerate()
    {
        store.save(&config(t)).expect("save");
        assert_eq!(store.load(), Some(config(t)), "after save {i}");
    }
    // Three records per region: saves 1–3 in the first, 4–6 in the second (erased first), 7–9
    // in the first (erased), 10 in the second (erased again).
    let [a, b] = store.into_inner();
    assert_eq!((a.erases, b.erases), (1, 2));
}

/// Every save of a sequence that makes the regions take turns twice, cut at every step of its
/// flash work: after the cut the store loads either the configuration before that save or the
/// one being saved — never nothing, never another — and the next save works and wins.
#[test]
fn a_power_cut_at_any_step_of_a_save_or_an_erase_keeps_a_configuration() {
    const RECORDS: usize = 3;
    let saves: Vec<Saved> = (0..8).map(|i| config(10.0 + i as f32)).collect();
    let mut cuts_tried = 0;
    for (n, target) in saves.iter().enumerate() {
        let mut cut = 0;
        loop {
            // The saves before this one, on an uncut supply.
            let power = Power::default();
            let mut store = LogStore::new(pair(RECORDS, &power));
            for c in &saves[..n] {
                store.save(c).expect("save before the cut");
            }
            let before = n.checked_sub(1).map(|i| saves[i]);
            power.set(Some(cut));
            let result = store.save(target);
            let finished = power.get() != Some(0) || result.is_ok();
            // Power back: a new store over the same flash.
            power.set(None);
            let mut store = LogStore::new(store.into_inner());
            let loaded = store.load();
            if finished {
                assert_eq!(result, Ok(()));
                assert_eq!(loaded, Some(*target), "save {n} with {cut} steps of power");
                break;
            }
            cuts_tried += 1;
            assert!(
                loaded == before || loaded == Some(*target),
                "save {n} cut after {cut} steps: loaded {:?}",
                loaded.map(|s| s.config.temperature_c)
            );
            // Another configuration is saved after the restart and wins.
            let after = config(40.0);
            store.save(&after).expect("save after the cut");
            assert_eq!(
                store.load(),
                Some(after),
                "save {n} cut after {cut} steps, then saved again"
            );
            cut += 1;
        }
    }
    // 50 words per record, two steps per erase: every step of every save was cut.
    assert!(cuts_tried >= 8 * 50, "{cuts_tried}");
}

#[test]
fn a_corrupted_record_is_skipped() {
    let power = Power::default();
    let mut store = LogStore::new(pair(4, &power));
    store.save(&config(20.0)).expect("save");
    store.save(&config(21.0)).expect("save");
    let [mut a, b] = store.into_inner();
    a.bytes[RECORD_LEN + 50] ^= 0x10;
    assert_eq!(LogStore::new([a, b]).load(), Some(config(20.0)));
}

#[test]
fn records_carry_their_layout_and_another_layout_is_skipped() {
    let power = Power::default();
    let mut store = LogStore::new(pair(4, &power));
    store.save(&config(20.0)).expect("save");
    store.save(&config(21.0)).expect("save");
    let [mut a, b] = store.into_inner();
    let (first, second) = (0..RECORD_LEN, RECORD_LEN..2 * RECORD_LEN);
    assert_eq!(a.bytes[first.end - 5], LAYOUT);
    // A record of a future layout, with a good CRC: skipped, the older one loads.
    let rec = &mut a.bytes[second];
    rec[RECORD_LEN - 5] = LAYOUT + 1;
    let crc = CRC.checksum(&rec[..RECORD_LEN - 4]);
    rec[RECORD_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    let mut store = LogStore::new([a, b]);
    assert_eq!(store.load(), Some(config(20.0)));
    // The layout before (1: 200-byte records of protocol 1's configuration) is not misread.
    let [_, b] = store.into_inner();
    let mut a = RamFlash::new(4, &power);
    let mut old = vec![0u8; 200];
    old[..4].copy_from_slice(b"PCFG");
    let crc = CRC.checksum(&old[..196]);
    old[196..].copy_from_slice(&crc.to_le_bytes());
    a.bytes[..200].copy_from_slice(&old);
    assert_eq!(LogStore::new([a, b]).load(), None);
}

#[test]
fn the_head_mode_is_saved_with_the_configuration() {
    let power = Power::default();
    let mut store = LogStore::new(pair(4, &power));
    let on = Saved {
        head: true,
        ..config(20.0)
    };
    store.save(&on).expect("save");
    assert_eq!(store.load(), Some(on));
    // Power cycled: a new store over the same flash.
    let mut store = LogStore::new(store.into_inner());
    assert_eq!(store.load(), Some(on));
    store.save(&config(20.0)).expect("save");
    assert_eq!(store.load(), Some(config(20.0)), "head off saved later wins");
    // Layout 3: the head byte just before the layout byte; its other bits must be zero.
    let [mut a, b] = store.into_inner();
    let second = RECORD_LEN..2 * RECORD_LEN;
    let rec = &mut a.bytes[second];
    assert_eq!((rec[RECORD_LEN - 6], rec[RECORD_LEN - 5]), (0, LAYOUT));
    rec[RECORD_LEN - 6] = 0x02;
    let crc = CRC.checksum(&rec[..RECORD_LEN - 4]);
    rec[RECORD_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(LogStore::new([a, b]).load(), Some(on), "a reserved head bit: skipped");
}

/// A record as firmware before head tracking wrote it (layout 2): magic, sequence, the whole
/// configuration report, the layout byte 2, the CRC. Built here byte by byte from the record
/// layout in docs/firmware.md, not by the store.
fn layout_2_record(seq: u32, config: &Config) -> Vec<u8> {
    let mut rec = vec![0u8; RECORD_LEN];
    rec[..4].copy_from_slice(b"PCFG");
    rec[4..8].copy_from_slice(&seq.to_le_bytes());
    config.encode(&mut rec[8..8 + Config::LEN]).expect("fits");
    rec[RECORD_LEN - 5] = 2;
    let crc = CRC.checksum(&rec[..RECORD_LEN - 4]);
    rec[RECORD_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    rec
}

#[test]
fn a_configuration_saved_before_the_head_mode_still_loads_with_the_head_off() {
    let power = Power::default();
    let [mut a, b] = pair(4, &power);
    let old = config(23.5).config;
    a.bytes[..RECORD_LEN].copy_from_slice(&layout_2_record(7, &old));
    let mut store = LogStore::new([a, b]);
    assert_eq!(
        store.load(),
        Some(Saved {
            config: old,
            head: false
        })
    );
    // The next save follows it (layout 3) and wins; the old record stays readable.
    let on = Saved {
        head: true,
        ..config(24.0)
    };
    store.save(&on).expect("save");
    assert_eq!(store.load(), Some(on));
    let [a, _] = store.into_inner();
    assert_eq!(
        &a.bytes[RECORD_LEN + 4..RECORD_LEN + 8],
        &8u32.to_le_bytes(),
        "sequence after 7"
    );
    // Without the new record, the old one alone still loads.
    let [mut a, b] = pair(4, &power);
    a.bytes[..RECORD_LEN].copy_from_slice(&layout_2_record(7, &old));
    a.bytes[RECORD_LEN..2 * RECORD_LEN].copy_from_slice(&layout_2_record(8, &config(25.0).config));
    assert_eq!(LogStore::new([a, b]).load(), Some(config(25.0)));
}
