//! What the installation files say: the systemd unit runs the installed pend, not a checkout
//! of the repository (issue 19.7), and the udev rules the tools' messages name are there.

use std::path::PathBuf;

fn repository_file(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-driver is in the repository")
        .join(path)
}

#[test]
fn the_unit_runs_the_installed_pend() {
    let unit = std::fs::read_to_string(repository_file("host-driver/systemd/pend.service")).expect("the unit");
    let settings: Vec<&str> = unit
        .lines()
        .map(str::trim)
        .filter(|l| !l.starts_with('#') && l.contains('='))
        .collect();
    // Where `cargo install --path host-driver --bin pend`, which the unit's comment gives, puts it.
    assert!(settings.contains(&"ExecStart=%h/.cargo/bin/pend"), "{settings:?}");
    assert!(unit.contains("cargo install --path host-driver --bin pend"));
    // No setting points into a checkout (the repository's folder is anyone's choice).
    for s in &settings {
        assert!(!s.contains("%h/penscape") && !s.contains("file://"), "{s}");
    }
}

#[test]
fn the_udev_rules_named_in_messages_exist() {
    let rules = std::fs::read_to_string(repository_file(pen_host::transport::UDEV_RULES)).expect("the rules");
    assert!(
        rules.contains("GROUP=\"plugdev\""),
        "the messages say the rules give the base station to plugdev"
    );
}
