//! The JSON forms (feature `serde`), golden: the exact text `penctl decode` has always printed
//! for these reports (docs/penctl.md), and the configuration read back from what it writes.

use crate::common;

use common::*;
use pen_protocol::*;

fn golden(m: Message, json: &str) {
    assert_eq!(serde_json::to_string(&m).expect("serializes"), json, "{m:?}");
}

fn decoded(hex: &str) -> Message {
    let s: String = hex.split_whitespace().collect();
    let bytes: Vec<u8> = (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect();
    Message::decode(&bytes).expect("a valid report")
}

#[test]
fn every_report_as_penctl_prints_it() {
    golden(
        Message::Pen(sample_pen()),
        r#"{"report_id":1,"report":"pen","sw1":true,"sw2":false,"sw3":true,"in_range":true,"display_frame":false,"x_mm":123.4,"y_mm":-56.7,"z_mm":89.0,"seq":4660,"timestamp_us":16909060,"quality":{"receivers_used":5,"residual_mm":0.7,"dop":1.8}}"#,
    );
    golden(
        decoded(
            "02 3412 04030201 04 0b 40420f00 60e31600 ffffffff 80841e00 ffffffff ffffffff ffffffff ffffffff 0080ab43",
        ),
        r#"{"report_id":2,"report":"time-of-flight","seq":4660,"timestamp_us":16909060,"tof_us":[1000.0,1500.0,null,2000.0],"used":[true,true,false,true],"speed_of_sound_m_s":343.0}"#,
    );
    golden(
        decoded("03 01 00 00 01 00 04 08 9600 000102030405060708090a0b"),
        r#"{"report_id":3,"report":"device information","protocol":"1.0","firmware":"0.1.0","receiver_count":4,"max_receivers":8,"fix_rate_hz":150,"unique_id":"000102030405060708090a0b"}"#,
    );
    golden(
        decoded("07 0b b80b a406"),
        r#"{"report_id":7,"report":"OS pen","tip":true,"barrel":true,"secondary_barrel":false,"in_range":true,"x_mm":300.0,"y_mm":170.0}"#,
    );
    golden(
        Message::Config(sample_config()),
        r#"{"report_id":4,"report":"configuration","receiver_count":4,"receivers_mm":[[0.0,0.0,0.0],[600.0,0.0,0.0],[0.0,400.0,150.0],[600.0,400.0,150.0]],"transducer_delay_us":[12.5,12.5,13.0,12.0],"temperature_c":21.5,"speed_of_sound_m_s":null,"report_rate_hz":150,"filter":{"kind":"one_euro","min_cutoff_hz":1.0,"beta":0.02,"d_cutoff_hz":1.0},"debounce_ms":5,"display":{"rotation_wxyz":[1.0,0.0,0.0,0.0],"translation_mm":[-10.0,20.0,0.0],"scale":1.0,"size_mm":[600.0,340.0]},"report_display_frame":false,"stream_tof":true}"#,
    );
    golden(
        decoded("05 04 03 12"),
        r#"{"report_id":5,"report":"status","request":4,"code":"OutOfRange","field":"receivers_mm[2]","message":"configuration (0x04) rejected: out of range (receivers_mm[2])"}"#,
    );
    golden(
        decoded("05 04 00 00"),
        r#"{"report_id":5,"report":"status","request":4,"code":"Ok","field":null,"message":"configuration (0x04) applied"}"#,
    );
    golden(
        decoded("06 02"),
        r#"{"report_id":6,"report":"command","command":"LoadDefaults"}"#,
    );
    golden(
        decoded("80 04"),
        r#"{"report_id":128,"report":"get-feature request","feature_report_id":4,"feature_report":"configuration"}"#,
    );
}

#[test]
fn a_report_alone_has_no_tag() {
    let text = serde_json::to_string(&sample_pen()).expect("serializes");
    assert!(text.starts_with(r#"{"sw1":true,"#), "{text}");
    let config = serde_json::to_string(&sample_config()).expect("serializes");
    assert!(config.starts_with(r#"{"receiver_count":4,"receivers_mm":"#), "{config}");
}

#[test]
fn the_configuration_reads_back() {
    let mut c = sample_config();
    c.speed_of_sound_m_s = Some(343.2);
    c.filter = Filter::Off;
    for c in [sample_config(), c] {
        let text = serde_json::to_string(&c).expect("serializes");
        let changes: ConfigChanges = serde_json::from_str(&text).expect("reads");
        let base = Config {
            receiver_count: 3,
            speed_of_sound_m_s: None,
            display: None,
            ..sample_config()
        };
        assert_eq!(changes.apply(&base), c, "{text}");
    }
}

#[test]
fn changes_keep_what_they_do_not_name() {
    let changes: ConfigChanges =
        serde_json::from_str(r#"{"temperature_c": 25, "speed_of_sound_m_s": 340, "display": null}"#).expect("reads");
    let c = changes.apply(&sample_config());
    assert_eq!(c.temperature_c, 25.0);
    assert_eq!(c.speed_of_sound_m_s, Some(340.0));
    assert_eq!(c.display, None);
    assert_eq!(c.receivers_mm, sample_config().receivers_mm);
    let back: ConfigChanges = serde_json::from_str(r#"{"speed_of_sound_m_s": null}"#).expect("reads");
    assert_eq!(back.apply(&c).speed_of_sound_m_s, None);
}

#[test]
fn malformed_settings_are_refused() {
    for bad in [
        r#"{"bogus": 1}"#,
        r#"{"receivers_mm": [[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0]]}"#,
        r#"{"receivers_mm": [[0,0]]}"#,
        r#"{"filter": {"kind": "one_euro", "beta": 1}}"#,
        r#"{"filter": {"kind": "off", "beta": 1}}"#,
        r#"{"display": {"rotation_wxyz": [1,0,0,0], "translation_mm": [0,0,0]}}"#,
        r#"{"debounce_ms": 256}"#,
        r#"{"stream_tof": 1}"#,
    ] {
        assert!(serde_json::from_str::<ConfigChanges>(bad).is_err(), "{bad}");
    }
}
