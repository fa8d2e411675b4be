//! Flashing from a fresh machine (docs/flashing.md): the firmware's toolchain file names the
//! board's target, and the udev rules the document installs are well formed and cover the
//! probes it names. (`scripts/test.sh` builds the `.bin` and checks its vector table.)

use std::path::Path;
use std::process::Command;

fn repo(path: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The value of `key = …` in a small TOML file, unparsed.
fn toml_value(text: &str, key: &str) -> Option<String> {
    text.lines().filter(|l| !l.trim_start().starts_with('#')).find_map(|l| {
        let (k, v) = l.split_once('=')?;
        (k.trim() == key).then(|| v.trim().to_string())
    })
}

#[test]
fn the_firmware_toolchain_file_names_the_boards_target() {
    let toolchain = repo("firmware/rust-toolchain.toml");
    let config = repo("firmware/.cargo/config.toml");
    let target = toml_value(&config, "target").expect("firmware/.cargo/config.toml sets build.target");
    let targets = toml_value(&toolchain, "targets").expect("rust-toolchain.toml lists targets");
    assert!(
        targets.contains(&target),
        "rust-toolchain.toml's targets {targets} lack the build target {target}: `cargo run` in \
         firmware/ would fail with \"can't find crate for core\" on a fresh machine"
    );
    // A channel that rustup can install: stable (the firmware needs 1.88 or later).
    assert_eq!(toml_value(&toolchain, "channel").as_deref(), Some("\"stable\""));
}

#[test]
fn the_firmware_sets_vtor_and_the_stack_pointer_at_reset() {
    // After `dfu-util … :leave` the ROM bootloader jumps to the image with VTOR at its own
    // table: without cortex-m-rt's set-vtor the first interrupt would run the ROM's handler.
    // (hil-tests/tests/qemu.rs checks the mechanism on pen-qemu, started the way the ROM does.)
    let manifest = repo("firmware/Cargo.toml");
    let rt = toml_value(&manifest, "cortex-m-rt").expect("firmware/Cargo.toml depends on cortex-m-rt");
    for feature in ["\"set-vtor\"", "\"set-sp\"", "\"paint-stack\""] {
        assert!(rt.contains(feature), "cortex-m-rt lacks {feature}: {rt}");
    }
}

/// One `KEY{attr}OP"value"` of a rule.
#[derive(Debug)]
struct Pair {
    key: String,
    attr: Option<String>,
    op: String,
    value: String,
}

const MATCH_KEYS: &[&str] = &[
    "ACTION",
    "DEVPATH",
    "KERNEL",
    "NAME",
    "SYMLINK",
    "SUBSYSTEM",
    "DRIVER",
    "ATTR",
    "KERNELS",
    "SUBSYSTEMS",
    "DRIVERS",
    "ATTRS",
    "TAGS",
    "ENV",
    "TAG",
    "PROGRAM",
    "RESULT",
];
const ASSIGN_KEYS: &[&str] = &[
    "NAME", "SYMLINK", "OWNER", "GROUP", "MODE", "TAG", "ENV", "ATTR", "RUN", "LABEL", "GOTO", "OPTIONS",
];

/// Splits a rule line into its pairs, or says what is wrong with it (udev(7)'s syntax).
fn parse_rule(line: &str) -> Result<Vec<Pair>, String> {
    let mut pairs = Vec::new();
    let mut rest = line.trim();
    while !rest.is_empty() {
        let key_end = rest
            .find(|c: char| !(c.is_ascii_uppercase() || c == '_'))
            .ok_or("a key without an operator")?;
        let key = &rest[..key_end];
        rest = &rest[key_end..];
        let attr = if let Some(r) = rest.strip_prefix('{') {
            let end = r.find('}').ok_or("an unclosed {")?;
            let attr = &r[..end];
            rest = &r[end + 1..];
            Some(attr.to_string())
        } else {
            None
        };
        let op = ["==", "!=", "+=", "-=", ":=", "="]
            .into_iter()
            .find(|op| rest.starts_with(op))
            .ok_or_else(|| format!("{key}: no operator"))?;
        rest = rest[op.len()..]
            .strip_prefix('"')
            .ok_or_else(|| format!("{key}: value not quoted"))?;
        let end = rest.find('"').ok_or_else(|| format!("{key}: value not closed"))?;
        let value = rest[..end].to_string();
        rest = rest[end + 1..].trim_start();
        if let Some(r) = rest.strip_prefix(',') {
            rest = r.trim_start();
            if rest.is_empty() {
                return Err("a trailing comma".into());
            }
        } else if !rest.is_empty() {
            return Err(format!("{key}: no comma before {rest:?}"));
        }
        let matching = op == "==" || op == "!=";
        let known = if matching { MATCH_KEYS } else { ASSIGN_KEYS };
        if !known.contains(&key) {
            return Err(format!("{key} cannot take {op}"));
        }
        if matches!(key, "ATTR" | "ATTRS" | "ENV") && attr.is_none() {
            return Err(format!("{key} needs {{name}}"));
        }
        if matches!(attr.as_deref(), Some("idVendor" | "idProduct"))
            && !(value.len() == 4 && value.chars().all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c)))
        {
            return Err(format!(
                "{key}{{{}}}: {value:?} is not four lower-case hex digits",
                attr.unwrap_or_default()
            ));
        }
        if key == "MODE" && !(value.len() >= 3 && value.chars().all(|c| ('0'..='7').contains(&c))) {
            return Err(format!("MODE {value:?} is not octal"));
        }
        pairs.push(Pair {
            key: key.to_string(),
            attr,
            op: op.to_string(),
            value,
        });
    }
    if pairs.iter().all(|p| p.op == "==" || p.op == "!=") && !pairs.is_empty() {
        return Err("a rule that matches but assigns nothing".into());
    }
    Ok(pairs)
}

/// Every rule of a rules file, or the first line that is wrong.
fn rules(file: &str) -> Vec<Vec<Pair>> {
    let text = repo(file);
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match parse_rule(line) {
            Ok(pairs) => out.push(pairs),
            Err(e) => panic!("{file}:{}: {e}\n{line}", n + 1),
        }
    }
    // Every GOTO has its LABEL.
    let labels: Vec<&str> = out
        .iter()
        .flatten()
        .filter(|p| p.key == "LABEL")
        .map(|p| p.value.as_str())
        .collect();
    for p in out.iter().flatten().filter(|p| p.key == "GOTO") {
        assert!(
            labels.contains(&p.value.as_str()),
            "{file}: GOTO {:?} has no LABEL",
            p.value
        );
    }
    out
}

fn grants(rules: &[Vec<Pair>], vendor: &str, product: &str) -> bool {
    rules.iter().any(|r| {
        let has = |attr: &str, v: &str| {
            r.iter()
                .any(|p| p.attr.as_deref() == Some(attr) && p.op == "==" && p.value == v)
        };
        has("idVendor", vendor)
            && (has("idProduct", product) || !r.iter().any(|p| p.attr.as_deref() == Some("idProduct")))
            && r.iter().any(|p| p.key == "TAG" && p.value == "uaccess")
    })
}

#[test]
fn the_udev_rules_parse_and_cover_the_probes_and_the_pen() {
    let probes = rules("firmware/udev/69-probe.rules");
    for (what, vid, pid) in [
        ("ST-LINK/V2", "0483", "3748"),
        ("ST-LINK/V2-1", "0483", "374b"),
        ("ST-LINK/V2-1 without mass storage", "0483", "3752"),
        ("STLINK-V3", "0483", "374f"),
        ("Raspberry Pi Debug Probe (CMSIS-DAP)", "2e8a", "000c"),
        ("DAPLink (CMSIS-DAP)", "0d28", "0204"),
        ("J-Link", "1366", "0101"),
    ] {
        assert!(
            grants(&probes, vid, pid),
            "69-probe.rules: no access for the {what} ({vid}:{pid})"
        );
    }
    // Any CMSIS-DAP probe, by the product string the standard requires.
    assert!(
        probes.iter().any(|r| r
            .iter()
            .any(|p| p.attr.as_deref() == Some("product") && p.value.contains("CMSIS-DAP"))),
        "69-probe.rules: no rule for CMSIS-DAP probes by product string"
    );
    let pen = rules("host-driver/udev/70-penscape.rules");
    assert!(grants(&pen, "0483", "df11"), "70-penscape.rules: the DFU bootloader");
    assert!(grants(&pen, "1209", "0007"), "70-penscape.rules: the pen");

    // udev's own check, where this machine has one (systemd 253 or later).
    match Command::new("udevadm")
        .arg("verify")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/udev/69-probe.rules"))
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("../host-driver/udev/70-penscape.rules"))
        .output()
    {
        Ok(out) if String::from_utf8_lossy(&out.stderr).contains("Unknown command") => {
            eprintln!("udevadm has no verify (systemd < 253): the rules are checked by this test's parser only")
        }
        Ok(out) => assert!(
            out.status.success(),
            "udevadm verify: {}",
            String::from_utf8_lossy(&out.stderr)
        ),
        Err(_) => eprintln!("no udevadm: the rules are checked by this test's parser only"),
    }
}

#[test]
fn the_rule_parser_refuses_what_udev_refuses() {
    for bad in [
        r#"ATTRS{idVendor}=="0483" MODE="660""#,
        r#"ATTRS{idVendor}=="483", MODE="660""#,
        r#"ATTRS{idVendor}==0483, MODE="660""#,
        r#"ATTRS{idVendor}=="0483", MODE="66x""#,
        r#"ATTRS{idVendor}=="0483", MODE=="660""#,
        r#"ATTRS{idVendor}=="0483","#,
        r#"ATTRS=="0483", MODE="660""#,
        r#"ATTRS{idVendor}=="0483""#,
    ] {
        assert!(parse_rule(bad).is_err(), "{bad}");
    }
    assert!(parse_rule(r#"ATTRS{idVendor}=="0483", MODE="660", TAG+="uaccess""#).is_ok());
}
