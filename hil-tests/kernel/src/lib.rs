//! The pen as a real Linux kernel sees it.
//!
//! Debian's own kernel (the `linux-image-amd64` package's, its `hid`, `uhid`, `hid-generic`,
//! `evdev` and `uinput` modules) and a static busybox (`busybox-static`) are fetched with
//! `apt-get download`, an initramfs is built holding them, the test programs (static, for
//! `x86_64-unknown-linux-musl`) and their data, and QEMU boots it: KVM where `/dev/kvm` opens,
//! TCG otherwise. Inside, `/init` loads the modules and runs `pen-kernel-guest`'s steps (the
//! descriptor and the firmware core's reports through uhid read back from evdev, `pend` on the
//! hidraw node, pend's virtual tablet refused without `/dev/uinput` and then made); each step
//! prints `KT` lines on the serial console, which [`boot`] collects.
//!
//! The host side is this library; the guest side is `src/bin/pen-kernel-guest.rs`. The lines
//! the guest prints are parsed by [`Run::parse`].

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};

/// The modules the tests need, by name; their dependencies are found from their `.modinfo`.
pub const MODULES: &[&str] = &["hid", "uhid", "hid-generic", "evdev", "uinput"];

/// Where the kernel's pieces are kept: `target/kernel` of the host workspace.
pub fn work_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/kernel"))
}

/// Debian's kernel, unpacked.
#[derive(Debug, Clone)]
pub struct Kernel {
    /// The kernel package, `linux-image-6.1.0-NN-amd64`.
    pub package: String,
    /// Its version string (`uname -r`).
    pub release: String,
    /// The bzImage.
    pub vmlinuz: PathBuf,
    /// The modules to load, in dependency order: (name, uncompressed `.ko` bytes' path).
    pub modules: Vec<(String, PathBuf)>,
    /// busybox, static.
    pub busybox: PathBuf,
}

/// Why the kernel could not be had: the test is skipped with this, never passed.
#[derive(Debug)]
pub struct Unavailable(pub String);

impl std::fmt::Display for Unavailable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

fn run(cmd: &mut Command) -> Result<String> {
    let out = cmd
        .stdin(Stdio::null())
        .output()
        .with_context(|| format!("cannot run {cmd:?}"))?;
    if !out.status.success() {
        bail!(
            "{cmd:?} failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The kernel package `linux-image-amd64` depends on, from apt's lists (updated once when they
/// do not know it).
fn kernel_package() -> Result<String> {
    let find = || -> Result<Option<String>> {
        let deps = run(Command::new("apt-cache").args(["depends", "linux-image-amd64"]))?;
        Ok(deps.lines().find_map(|l| {
            let name = l.trim().strip_prefix("Depends: ")?;
            (name.starts_with("linux-image-") && name.as_bytes().get(12).is_some_and(u8::is_ascii_digit))
                .then(|| name.to_string())
        }))
    };
    if let Ok(Some(p)) = find() {
        return Ok(p);
    }
    run(Command::new("apt-get").args(["update", "-qq"]))?;
    find()?.ok_or_else(|| anyhow!("apt knows no kernel package behind linux-image-amd64"))
}

/// `apt-get download`s `package` into `dir` (once) and returns the `.deb`.
fn download(package: &str, dir: &Path) -> Result<PathBuf> {
    let find = || -> Result<Option<PathBuf>> {
        Ok(std::fs::read_dir(dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(&format!("{package}_")) && n.ends_with(".deb"))
            }))
    };
    if let Some(p) = find()? {
        return Ok(p);
    }
    run(Command::new("apt-get")
        .args(["download", "-qq", package])
        .current_dir(dir))?;
    find()?.ok_or_else(|| anyhow!("apt-get download {package} left no .deb"))
}

/// Unpacks the paths matching `patterns` of `deb` into `dest`.
fn unpack(deb: &Path, dest: &Path, patterns: &[&str]) -> Result<()> {
    std::fs::create_dir_all(dest)?;
    let tar = format!(
        "dpkg-deb --fsys-tarfile '{}' | tar -x -C '{}' --wildcards {}",
        deb.display(),
        dest.display(),
        patterns.iter().map(|p| format!("'{p}'")).collect::<Vec<_>>().join(" ")
    );
    run(Command::new("sh").args(["-c", &tar]))?;
    Ok(())
}

/// A module's `depends=` from its `.modinfo` section.
fn depends(ko: &[u8]) -> Vec<String> {
    ko.split(|&b| b == 0)
        .find_map(|s| s.strip_prefix(b"depends="))
        .map(|d| {
            String::from_utf8_lossy(d)
                .split(',')
                .filter(|s| !s.is_empty())
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default()
}

/// A module's bytes, decompressed when the package compressed it (busybox's insmod takes plain
/// `.ko` only).
fn module_bytes(path: &Path) -> Result<Vec<u8>> {
    let name = path.to_string_lossy();
    let tool = if name.ends_with(".ko.xz") {
        Some("xz")
    } else if name.ends_with(".ko.zst") {
        Some("zstd")
    } else if name.ends_with(".ko.gz") {
        Some("gzip")
    } else {
        None
    };
    match tool {
        None => Ok(std::fs::read(path)?),
        Some(tool) => {
            let out = Command::new(tool)
                .arg("-dc")
                .arg(path)
                .output()
                .with_context(|| format!("{tool} decompresses {name}"))?;
            if !out.status.success() {
                bail!("{tool} -dc {name} failed");
            }
            Ok(out.stdout)
        }
    }
}

/// Module names treat `-` and `_` alike.
fn module_key(name: &str) -> String {
    name.replace('-', "_")
}

impl Kernel {
    /// Fetches (once; later runs reuse `target/kernel`) and unpacks Debian's kernel and busybox.
    pub fn fetch() -> Result<Kernel, Unavailable> {
        Kernel::fetch_into(&work_dir()).map_err(|e| Unavailable(format!("{e:#}")))
    }

    fn fetch_into(dir: &Path) -> Result<Kernel> {
        let debs = dir.join("debs");
        std::fs::create_dir_all(&debs)?;
        let package = kernel_package()?;
        let release = package
            .strip_prefix("linux-image-")
            .ok_or_else(|| anyhow!("odd kernel package {package}"))?
            .to_string();
        let root = dir.join(&package);
        if !root.join(".unpacked").exists() {
            let deb = download(&package, &debs)?;
            let _ = std::fs::remove_dir_all(&root);
            unpack(
                &deb,
                &root,
                &[
                    "./boot/vmlinuz-*",
                    "./lib/modules/*/kernel/drivers/hid/*",
                    "./lib/modules/*/kernel/drivers/input/*",
                ],
            )?;
            std::fs::write(root.join(".unpacked"), b"")?;
        }
        let bb_root = dir.join("busybox-static");
        if !bb_root.join(".unpacked").exists() {
            let deb = download("busybox-static", &debs)?;
            unpack(&deb, &bb_root, &["./bin/busybox"])?;
            std::fs::write(bb_root.join(".unpacked"), b"")?;
        }
        let vmlinuz = root.join(format!("boot/vmlinuz-{release}"));
        if !vmlinuz.exists() {
            bail!("{package} has no boot/vmlinuz-{release}");
        }
        // Every module file unpacked, by name.
        let mut found: BTreeMap<String, PathBuf> = BTreeMap::new();
        let mut stack = vec![root.join(format!("lib/modules/{release}"))];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).with_context(|| format!("{}", d.display()))? {
                let p = e?.path();
                if p.is_dir() {
                    stack.push(p);
                } else if let Some(name) = p.file_name().and_then(|n| n.to_str())
                    && let Some(stem) = [".ko", ".ko.xz", ".ko.zst", ".ko.gz"]
                        .iter()
                        .find_map(|ext| name.strip_suffix(ext))
                {
                    found.insert(module_key(stem), p.clone());
                }
            }
        }
        // Dependencies first, each once; plain .ko files under target/kernel/ko.
        let ko_dir = dir.join("ko").join(&release);
        std::fs::create_dir_all(&ko_dir)?;
        let mut modules: Vec<(String, PathBuf)> = Vec::new();
        fn visit(
            name: &str,
            found: &BTreeMap<String, PathBuf>,
            ko_dir: &Path,
            out: &mut Vec<(String, PathBuf)>,
            depth: usize,
        ) -> Result<()> {
            let key = module_key(name);
            if out.iter().any(|(n, _)| module_key(n) == key) {
                return Ok(());
            }
            if depth > 16 {
                bail!("module dependencies loop at {name}");
            }
            let src = found
                .get(&key)
                .ok_or_else(|| anyhow!("module {name} is not among drivers/hid and drivers/input"))?;
            let bytes = module_bytes(src)?;
            for dep in depends(&bytes) {
                visit(&dep, found, ko_dir, out, depth + 1)?;
            }
            let plain = ko_dir.join(format!("{key}.ko"));
            std::fs::write(&plain, &bytes)?;
            out.push((name.to_string(), plain));
            Ok(())
        }
        for m in MODULES {
            visit(m, &found, &ko_dir, &mut modules, 0)?;
        }
        Ok(Kernel {
            package,
            release,
            vmlinuz,
            modules,
            busybox: bb_root.join("bin/busybox"),
        })
    }
}

/// A newc ("070701") cpio archive, the initramfs format the kernel unpacks.
#[derive(Default)]
pub struct Cpio {
    bytes: Vec<u8>,
    inode: u32,
}

impl Cpio {
    fn entry(&mut self, name: &str, mode: u32, data: &[u8]) {
        self.inode += 1;
        let name_z = name.len() + 1;
        let header = format!(
            "070701{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}{:08x}",
            self.inode,
            mode,
            0,
            0,
            1,
            0,
            data.len(),
            0,
            0,
            0,
            0,
            name_z,
            0
        );
        self.bytes.extend_from_slice(header.as_bytes());
        self.bytes.extend_from_slice(name.as_bytes());
        self.bytes.push(0);
        self.pad();
        self.bytes.extend_from_slice(data);
        self.pad();
    }

    fn pad(&mut self) {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
    }

    /// A directory.
    pub fn dir(&mut self, name: &str) {
        self.entry(name, 0o040755, &[]);
    }

    /// A file with `mode`'s permission bits.
    pub fn file(&mut self, name: &str, mode: u32, data: &[u8]) {
        self.entry(name, 0o100000 | mode, data);
    }

    /// The archive, with its trailer.
    pub fn finish(mut self) -> Vec<u8> {
        self.entry("TRAILER!!!", 0, &[]);
        self.bytes
    }
}

/// What the initramfs holds beside the kernel's pieces.
pub struct Guest {
    /// `/bin/NAME` programs: (name, static executable).
    pub programs: Vec<(String, PathBuf)>,
    /// `/data/NAME` files.
    pub data: Vec<(String, Vec<u8>)>,
    /// The steps `/init` runs after loading the modules: shell lines.
    pub steps: Vec<String>,
}

/// The initramfs: busybox, the modules, the guest's programs and data, and an `/init` that
/// mounts proc, sys and devtmpfs (which makes `/dev/uhid`, `/dev/uinput`, `/dev/hidraw*` and
/// `/dev/input/event*` with no udev), loads the modules in order, runs the steps and powers off.
pub fn initramfs(kernel: &Kernel, guest: &Guest) -> Result<Vec<u8>> {
    let mut c = Cpio::default();
    for d in [
        "bin",
        "sbin",
        "dev",
        "proc",
        "sys",
        "tmp",
        "run",
        "data",
        "lib",
        "lib/modules",
    ] {
        c.dir(d);
    }
    c.file("bin/busybox", 0o755, &std::fs::read(&kernel.busybox)?);
    let mut init = String::from(
        "#!/bin/busybox sh\n\
         /bin/busybox --install -s /bin\n\
         export PATH=/bin:/sbin\n\
         mount -t proc proc /proc\n\
         mount -t sysfs sys /sys\n\
         mount -t devtmpfs dev /dev\n\
         mount -t tmpfs tmp /tmp\n\
         mount -t tmpfs run /run\n\
         echo \"KT uname $(uname -r)\"\n",
    );
    for (name, path) in &kernel.modules {
        let file = format!("lib/modules/{}.ko", module_key(name));
        c.file(&file, 0o644, &std::fs::read(path)?);
        init.push_str(&format!(
            "insmod /{file} && echo 'KT module {name}' || echo 'KT FAIL insmod {name}'\n"
        ));
    }
    for (name, path) in &guest.programs {
        c.file(
            &format!("bin/{name}"),
            0o755,
            &std::fs::read(path).with_context(|| format!("{}", path.display()))?,
        );
    }
    for (name, data) in &guest.data {
        c.file(&format!("data/{name}"), 0o644, data);
    }
    for step in &guest.steps {
        init.push_str(step);
        init.push('\n');
    }
    init.push_str("echo 'KT DONE'\nsync\npoweroff -f\n");
    c.file("init", 0o755, init.as_bytes());
    Ok(c.finish())
}

/// How QEMU ran the machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Accel {
    /// Hardware virtualisation (`/dev/kvm` opened).
    Kvm,
    /// QEMU's own translator.
    Tcg,
}

impl Accel {
    /// KVM where `/dev/kvm` opens for reading and writing, TCG otherwise.
    pub fn detect() -> Accel {
        match std::fs::OpenOptions::new().read(true).write(true).open("/dev/kvm") {
            Ok(_) => Accel::Kvm,
            Err(_) => Accel::Tcg,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Accel::Kvm => "KVM",
            Accel::Tcg => "TCG",
        }
    }
}

/// A finished boot: the `KT` lines the guest printed, the console's whole text, how long.
#[derive(Debug)]
pub struct Run {
    /// The accelerator.
    pub accel: Accel,
    /// From QEMU's start to its exit.
    pub elapsed: Duration,
    /// The `KT` lines, without the prefix.
    pub lines: Vec<String>,
    /// Everything on the console.
    pub console: String,
}

impl Run {
    /// Parses the console's text.
    pub fn parse(accel: Accel, elapsed: Duration, console: String) -> Run {
        let lines = console
            .lines()
            .filter_map(|l| {
                l.trim_end_matches('\r')
                    .split_once("KT ")
                    .map(|(_, rest)| rest.to_string())
            })
            .collect();
        Run {
            accel,
            elapsed,
            lines,
            console,
        }
    }

    /// The lines starting with `word`, the word taken off.
    pub fn with<'a>(&'a self, word: &'a str) -> impl Iterator<Item = &'a str> + 'a {
        self.lines
            .iter()
            .filter_map(move |l| l.strip_prefix(word).map(str::trim_start))
    }

    /// Whether the guest reached the end of `/init`.
    pub fn finished(&self) -> bool {
        self.lines.iter().any(|l| l == "DONE")
    }
}

/// The kernel's first line on the early console (`earlycon`), printed before its command line
/// is parsed and so whatever the `loglevel`: the kernel proper runs.
pub const KERNEL_STARTED: &[u8] = b"Linux version";

/// How long KVM has to print [`KERNEL_STARTED`]. Under KVM the kernel starts within a fraction
/// of a second of QEMU (TCG needs about 4 s for the decompressor alone); under a nested KVM
/// that opens but cannot run the kernel, the firmware prints "Booting from ROM..." and then
/// nothing comes.
pub const KVM_START: Duration = Duration::from_secs(5);

/// Boots `kernel` with `initramfs` in QEMU (1 GiB, serial console) and waits for it to power
/// off, at most `timeout`; with KVM, fails when the kernel has not started within
/// [`KVM_START`].
pub fn boot(kernel: &Kernel, initramfs: &[u8], accel: Accel, timeout: Duration) -> Result<Run> {
    let first_line = match accel {
        Accel::Kvm => KVM_START,
        Accel::Tcg => timeout,
    };
    let dir = work_dir().join("run");
    std::fs::create_dir_all(&dir)?;
    let image = dir.join(format!("initramfs-{}.cpio", std::process::id()));
    std::fs::write(&image, initramfs)?;
    let mut cmd = Command::new("qemu-system-x86_64");
    cmd.args([
        "-m",
        "1024",
        "-smp",
        "1",
        "-nographic",
        "-no-reboot",
        "-monitor",
        "none",
    ])
    .arg("-kernel")
    .arg(&kernel.vmlinuz)
    .arg("-initrd")
    .arg(&image)
    .args([
        "-append",
        "console=ttyS0 earlycon=uart8250,io,0x3f8,115200 panic=-1 loglevel=4 rdinit=/init",
    ]);
    match accel {
        // QEMU's default CPU model: `-cpu host` passes MSRs a nested KVM may refuse.
        Accel::Kvm => cmd.args(["-enable-kvm"]),
        Accel::Tcg => cmd.args(["-accel", "tcg"]),
    };
    let start = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot run qemu-system-x86_64 (scripts/setup.sh installs qemu-system-x86)")?;
    let mut stdout = child.stdout.take().ok_or_else(|| anyhow!("no stdout"))?;
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::<u8>::new()));
    let shared = seen.clone();
    let reader = std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        while let Ok(n) = stdout.read(&mut buf) {
            if n == 0 {
                break;
            }
            if let Ok(mut s) = shared.lock() {
                s.extend_from_slice(&buf[..n]);
            }
        }
        shared
            .lock()
            .map(|s| String::from_utf8_lossy(&s).into_owned())
            .unwrap_or_default()
    });
    loop {
        if child.try_wait()?.is_some() {
            break;
        }
        // Under a nested KVM a machine can start and never run the kernel: no kernel line soon
        // means the accelerator does not work here.
        let started = seen
            .lock()
            .map(|s| s.windows(KERNEL_STARTED.len()).any(|w| w == KERNEL_STARTED))
            .unwrap_or(false);
        if !started && start.elapsed() > first_line {
            let _ = child.kill();
            let _ = child.wait();
            let _ = std::fs::remove_file(&image);
            bail!(
                "the kernel did not start within {first_line:?} with {} (no {:?} on the console)",
                accel.name(),
                String::from_utf8_lossy(KERNEL_STARTED)
            );
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            let console = reader.join().unwrap_or_default();
            let _ = std::fs::remove_file(&image);
            bail!("the virtual machine did not power off within {timeout:?}; its console:\n{console}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let elapsed = start.elapsed();
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut err);
    }
    let console = reader.join().map_err(|_| anyhow!("console reader panicked"))?;
    let _ = std::fs::remove_file(&image);
    if console.is_empty() {
        bail!("QEMU printed nothing: {err}");
    }
    Ok(Run::parse(accel, elapsed, console))
}

/// Builds the guest's programs static for `x86_64-unknown-linux-musl` (debug, in
/// `target/kernel/cargo`, apart from the workspace's own target so that the test's cargo lock
/// is not waited on): `pen-kernel-guest` and `pend`. Returns their paths.
pub fn build_guest_programs() -> Result<Vec<(String, PathBuf)>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let target_dir = work_dir().join("cargo");
    let root = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let out = Command::new(&cargo)
        .args([
            "build",
            "--locked",
            "-q",
            "--target",
            "x86_64-unknown-linux-musl",
            "-p",
            "pen-kernel",
            "--bin",
            "pen-kernel-guest",
            "-p",
            "pen-host",
            "--features",
            "pen-host/sim",
            "--bin",
            "pend",
        ])
        .env("CARGO_TARGET_DIR", &target_dir)
        .current_dir(&root)
        .stdin(Stdio::null())
        .output()
        .with_context(|| format!("cannot run {cargo}"))?;
    if !out.status.success() {
        bail!(
            "building the guest's programs for x86_64-unknown-linux-musl failed (scripts/setup.sh adds the target):\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let bin = target_dir.join("x86_64-unknown-linux-musl/debug");
    Ok(["pen-kernel-guest", "pend"]
        .iter()
        .map(|n| (n.to_string(), bin.join(n)))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modinfo_dependencies_are_read() {
        let ko = b"\x7fELF...\0license=GPL\0depends=hid,usbhid\0vermagic=6.1\0";
        assert_eq!(depends(ko), ["hid", "usbhid"]);
        assert!(depends(b"\0depends=\0").is_empty());
        assert!(depends(b"nothing").is_empty());
    }

    #[test]
    fn cpio_entries_are_aligned_and_trailed() {
        let mut c = Cpio::default();
        c.dir("bin");
        c.file("init", 0o755, b"#!/bin/sh\n");
        let bytes = c.finish();
        assert_eq!(&bytes[..6], b"070701");
        assert_eq!(bytes.len() % 4, 0);
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("TRAILER!!!"));
        // The file's mode: regular, 0755.
        assert!(text.contains(&format!("{:08x}", 0o100755)));
    }

    #[test]
    fn console_lines_are_parsed() {
        let run = Run::parse(
            Accel::Tcg,
            Duration::from_secs(1),
            "[    0.1] boot\r\nKT module hid\r\nnoise KT PASS uhid\nKT DONE\n".into(),
        );
        assert_eq!(run.lines, ["module hid", "PASS uhid", "DONE"]);
        assert_eq!(run.with("PASS").collect::<Vec<_>>(), ["uhid"]);
        assert!(run.finished());
    }
}
