//! The reset record across a reset: sealed in RAM by a panic or a fault, taken back once by the
//! next boot, refused when the RAM holds anything else; answered as feature report 0x09.

use core::fmt::Write;

use pen_core::reset::{RamRecord, TextWriter};
use pen_core::{ConfigStore, Engine, Saved, StoreError};
use pen_protocol::*;

fn panic_record() -> ResetRecord {
    let mut r = ResetRecord {
        kind: ResetKind::Panic,
        line: 120,
        column: 9,
        uptime_ms: 4_200,
        ..ResetRecord::NONE
    };
    r.set_text("src/usb.rs:120:9: index out of bounds");
    r
}

#[test]
fn a_sealed_record_is_taken_once() {
    let mut slot = RamRecord::seal(&panic_record());
    assert_eq!(slot.take(), Some(panic_record()));
    // The next boot after an ordinary reset finds nothing.
    assert_eq!(slot.take(), None);
}

#[test]
fn ram_that_holds_anything_else_is_no_record() {
    // A power-up's RAM: patterns that are not a sealed record.
    for fill in [0x00u8, 0xFF, 0xA5] {
        let word = u32::from_le_bytes([fill; 4]);
        let mut slot = RamRecord::from_parts(word, [fill; ResetRecord::LEN], word);
        assert_eq!(slot.take(), None, "fill {fill:#x}");
    }
    // A sealed record with one bit flipped (the fault came while it was written).
    let (magic, mut bytes, crc) = RamRecord::seal(&panic_record()).parts();
    bytes[20] ^= 0x04;
    assert_eq!(RamRecord::from_parts(magic, bytes, crc).take(), None);
    // Intact, it is taken.
    bytes[20] ^= 0x04;
    assert_eq!(RamRecord::from_parts(magic, bytes, crc).take(), Some(panic_record()));
}

#[test]
fn the_text_writer_cuts_a_long_message_at_a_character() {
    let mut r = ResetRecord::NONE;
    let mut w = TextWriter::new(&mut r);
    write!(w, "src/main.rs:{}:{}: ", 77, 5).expect("never fails");
    write!(w, "{}", "ü".repeat(40)).expect("never fails, even when full");
    let text = r.text();
    assert!(text.starts_with("src/main.rs:77:5: ü"), "{text}");
    assert!(
        text.len() <= RESET_TEXT_LEN && text.len() >= RESET_TEXT_LEN - 1,
        "{}",
        text.len()
    );
    assert!(text.ends_with('ü'));
}

struct NoStore;
impl ConfigStore for NoStore {
    fn load(&mut self) -> Option<Saved> {
        None
    }
    fn save(&mut self, _: &Saved) -> Result<(), StoreError> {
        Err(StoreError::Flash)
    }
}

#[test]
fn the_engine_answers_the_record_and_refuses_writes() {
    let firmware = FirmwareVersion {
        major: 1,
        minor: 0,
        patch: 0,
    };
    let mut e = Engine::new(None, firmware, [1; 12]);
    let mut buf = [0u8; 64];
    let n = e.get_feature(ReportId::ResetRecord as u8, &mut buf).expect("answered");
    assert_eq!(ResetRecord::decode(&buf[..n]).expect("decodes"), ResetRecord::NONE);

    e.set_last_reset(panic_record());
    let n = e.get_feature(ReportId::ResetRecord as u8, &mut buf).expect("answered");
    assert_eq!(ResetRecord::decode(&buf[..n]).expect("decodes"), panic_record());

    // Over the serial link: the get-feature request answers it too.
    let mut request = [0u8; 8];
    let len = GetFeature {
        report: ReportId::ResetRecord,
    }
    .encode(&mut request)
    .expect("encodes");
    let mut answer = [0u8; MAX_PAYLOAD];
    let (n, _) = e.handle_request(&request[..len], &mut answer, &mut NoStore);
    let n = n.expect("an answer");
    assert_eq!(
        Message::decode(&answer[..n]).expect("decodes"),
        Message::ResetRecord(panic_record())
    );

    // Read-only.
    let n = panic_record().encode(&mut buf).expect("encodes");
    let (status, _) = e.set_feature(&buf[..n], &mut NoStore);
    assert_eq!(status.code, StatusCode::ReadOnly);
}
