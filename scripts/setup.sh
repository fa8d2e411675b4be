# Sourced by run.sh and test.sh: installs what a fresh Debian machine with rustup lacks.
# Idempotent and quiet when everything is already there.

# Debian packages the scripts need: binutils for `size` (firmware image figures), QEMU for the
# firmware core's run on an emulated Cortex-M4F (hil-tests/tests/qemu.rs) and for Debian's own
# kernel on x86-64 (hil-tests/kernel, which fetches the kernel and busybox with apt-get download);
# Xvfb, xdotool and xwd (x11-apps) for the modeler's window driven by a synthetic mouse (modeler/tests/
# mouse_window.rs), with the X libraries winit loads at run time.
DEB_PACKAGES=(binutils qemu-system-arm qemu-system-x86 xvfb xdotool x11-apps libxcursor1 libxrandr2 libxi6
    libxkbcommon-x11-0)
# The board's target, the bench rig's (Raspberry Pi Pico, hil-tests/rig), static x86-64 programs
# for the real-kernel test's initramfs; clippy and rustfmt for the checks.
RUST_TARGETS=(thumbv7em-none-eabihf thumbv6m-none-eabi x86_64-unknown-linux-musl)
RUST_COMPONENTS=(clippy rustfmt)
# SETUP=firmware (scripts/firmware-bin.sh): only what building the board's image needs, the
# target — no Debian packages, no emulator.
if [ "${SETUP:-}" = firmware ]; then
    DEB_PACKAGES=()
    RUST_TARGETS=(thumbv7em-none-eabihf)
    RUST_COMPONENTS=()
fi

setup() {
    local missing=()
    for pkg in "${DEB_PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
    done
    if ((${#missing[@]})); then
        echo "setup: installing Debian packages: ${missing[*]}" >&2
        local sudo=""
        [ "$(id -u)" -eq 0 ] || sudo="sudo"
        $sudo apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    fi

    local installed
    installed=$(rustup target list --installed)
    for t in "${RUST_TARGETS[@]}"; do
        grep -qx "$t" <<<"$installed" || { echo "setup: adding Rust target $t" >&2; rustup target add "$t" >/dev/null 2>&1; }
    done
    installed=$(rustup component list --installed)
    for c in "${RUST_COMPONENTS[@]}"; do
        grep -q "^$c" <<<"$installed" || { echo "setup: adding Rust component $c" >&2; rustup component add "$c" >/dev/null 2>&1; }
    done
}

setup
