//! Firmware of the pen's base station (STM32F411CE "Black Pill").
//!
//! This file only wires the hardware to the core (`pen-core`), in embassy's order: clocks,
//! interrupts, peripherals, the USB builder and its classes, then the tasks joined. All tracking
//! logic — ranges, solving, smoothing, debouncing, reports, configuration — lives in the core,
//! which the host tests and the simulated pen drive through the same traits this board
//! implements (`capture`, `switches`, `clock`, `usb`). Pins and wiring: docs/hardware.md.
#![no_std]
#![no_main]

mod bootloader;
mod capture;
mod clock;
mod crystal;
mod fault;
mod flash_store;
mod hard_fault;
mod stack;
mod switches;
mod time_driver;
mod usb;

use core::cell::RefCell;

use defmt::{debug, info, warn};
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_futures::join::{join, join3};
use embassy_futures::select::{Either, select};
use embassy_stm32::flash::Flash;
use embassy_stm32::gpio::{Input, Level, Output, Pull, Speed};
use embassy_stm32::time::Hertz;
use embassy_stm32::usb::Driver;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{Config, bind_interrupts, peripherals, uid};
use embassy_sync::blocking_mutex::Mutex;
use embassy_time::{Duration, Instant, Timer};
use embassy_usb::Builder;
use embassy_usb::class::cdc_acm::{self, CdcAcmClass};
use embassy_usb::class::hid::{self, HidBootProtocol, HidSubclass, HidWriter};
use pen_core::{ConfigStore, Engine, LogStore, Station, WakeOnPress};
use pen_protocol::{FirmwareVersion, PROTOCOL_VERSION, USB_PID, USB_VID, report_descriptor};

use crate::capture::{BoardRanging, Pins, burst_pin, capture_pin, glasses_pin};
use crate::clock::BoardClock;
use crate::flash_store::ConfigSector;
use crate::switches::BoardSwitches;
use crate::usb::{BoardSink, BusState, FeatureHandler, HID_PACKET, HidQueue, SerialQueue};

bind_interrupts!(struct Irqs {
    OTG_FS => embassy_stm32::usb::InterruptHandler<peripherals::USB_OTG_FS>;
    TIM2 => capture::Tim2Captures;
    TIM3 => capture::Tim3Captures;
    TIM5 => time_driver::Tim5Interrupt;
});

/// The watchdog resets the board if the station stops for this long. The longest the CPU ever
/// stalls is a 128 KiB flash sector erase, which embassy runs at 8-bit parallelism (PSIZE is
/// left 0): 2 s typical, 4 s at most (DS10314, t_ERASE128KB). The IWDG runs from the LSI, 17–47
/// kHz against the nominal 32: 12 s nominal is 8.2 s at the fastest LSI, twice the worst erase.
const WATCHDOG_US: u32 = 12_000_000;

/// Parses a decimal version component at compile time.
const fn parse_u8(s: &str) -> u8 {
    let b = s.as_bytes();
    let mut v: u32 = 0;
    let mut i = 0;
    while i < b.len() {
        assert!(b[i].is_ascii_digit(), "version component is not a number");
        v = v * 10 + (b[i] - b'0') as u32;
        i += 1;
    }
    assert!(v <= 255, "version component exceeds 255");
    v as u8
}

const FIRMWARE: FirmwareVersion = FirmwareVersion {
    major: parse_u8(env!("CARGO_PKG_VERSION_MAJOR")),
    minor: parse_u8(env!("CARGO_PKG_VERSION_MINOR")),
    patch: parse_u8(env!("CARGO_PKG_VERSION_PATCH")),
};

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    // A restart into the ROM bootloader must happen before anything is initialised.
    bootloader::enter_if_requested();
    bootloader::map_flash_at_zero();
    // What ended the previous run, if a panic, a fault or the watchdog did.
    let last_reset = fault::take_last();

    // Clocks: the crystal, measured (8 or 25 MHz; anything else blinks the LED for ever) → PLL:
    // 96 MHz system clock, 48 MHz for USB; APB1 48 MHz (its timers 96 MHz), APB2 96 MHz.
    let crystal = crystal::measure().unwrap_or_else(|fault| crystal::fault_blink(fault));
    let mut config = Config::default();
    {
        use embassy_stm32::rcc::*;
        let (m, n) = crystal.pll();
        config.rcc.hse = Some(Hse {
            freq: Hertz(crystal.hz()),
            mode: HseMode::Oscillator,
        });
        config.rcc.pll_src = PllSource::HSE;
        config.rcc.pll = Some(Pll {
            prediv: PllPreDiv::from_bits(m as u8),
            mul: PllMul::from_bits(n as u16),
            divp: Some(PllPDiv::DIV2),
            divq: Some(PllQDiv::DIV4),
            divr: None,
        });
        config.rcc.ahb_pre = AHBPrescaler::DIV1;
        config.rcc.apb1_pre = APBPrescaler::DIV2;
        config.rcc.apb2_pre = APBPrescaler::DIV1;
        config.rcc.sys = Sysclk::PLL1_P;
    }
    let p = embassy_stm32::init(config);
    time_driver::init();
    info!("pen base station, firmware {}, protocol {}", FIRMWARE, PROTOCOL_VERSION);
    info!("crystal: {} Hz", crystal.hz());
    if let Some(record) = &last_reset {
        warn!("the previous run ended unasked:");
        fault::log(record);
    }
    // The flash accelerator: embassy sets the wait states (3 at 96 MHz) and nothing else. Without
    // prefetch and the instruction and data caches, every fetch waits them out and the core runs
    // about half as fast as docs/firmware.md's figures assume (RM0383 §3.4).
    flash_store::enable_accelerator();
    // Freeze the watchdog while a debugger halts the core, so that probe-rs can read a panic's
    // backtrace without the chip resetting under it.
    embassy_stm32::pac::DBGMCU.apb1fzr().modify(|w| w.set_iwdg(true));

    let mut watchdog = IndependentWatchdog::new(p.IWDG, WATCHDOG_US);
    watchdog.unleash();

    // The configuration: the newest saved one, or the defaults.
    let flash = RefCell::new(Flash::new_blocking(p.FLASH));
    let store = Mutex::new(RefCell::new(LogStore::new(
        flash_store::SECTORS.map(|offset| ConfigSector { flash: &flash, offset }),
    )));
    let saved = store.lock(|s| s.borrow_mut().load());
    if saved.is_none() {
        info!("no saved configuration: using the defaults");
    }
    let engine = Mutex::new(RefCell::new(Engine::new(saved.map(|s| s.config), FIRMWARE, uid::uid())));
    // The glasses' emitter has its own channel (PA9): HeadOn may start head tracking, and a
    // SaveConfig while it ran starts it again here.
    let (receivers, head) = engine.lock(|e| {
        let mut e = e.borrow_mut();
        e.set_head_emitter_fitted(true);
        if let Some(record) = last_reset {
            e.set_last_reset(record);
        }
        (e.settings().count, e.resume_head(saved.is_some_and(|s| s.head)))
    });
    if head {
        info!("head tracking on, as saved");
    }

    // The boost converter's soft-start switch (docs/hardware.md, PB13): off until the host has
    // configured the device, and in suspend; USB allows no more before configuration.
    let mut boost = Output::new(p.PB13, Level::Low, Speed::Low);

    // The front end, the switches, the clock.
    let pins = Pins {
        burst: burst_pin(p.PA8),
        glasses: glasses_pin(p.PA9),
        tim2: (
            capture_pin(p.PA15),
            capture_pin(p.PB3),
            capture_pin(p.PB10),
            capture_pin(p.PA3),
        ),
        tim3: (
            capture_pin(p.PA6),
            capture_pin(p.PA7),
            capture_pin(p.PB0),
            capture_pin(p.PB1),
        ),
    };
    let ranging = BoardRanging::new(p.TIM1, p.TIM2, p.TIM3, pins, receivers);
    let switches = BoardSwitches {
        pins: [
            Input::new(p.PB12, Pull::Up),
            Input::new(p.PB14, Pull::Up),
            Input::new(p.PB15, Pull::Up),
        ],
    };

    // USB: a composite device with the HID pen and a CDC-ACM serial link. The Black Pill has no
    // VBUS sense, so VBUS detection stays off.
    let mut ep_out_buffer = [0u8; 256];
    let mut usb_config = embassy_stm32::usb::Config::default();
    usb_config.vbus_detection = false;
    let driver = Driver::new_fs(p.USB_OTG_FS, Irqs, p.PA12, p.PA11, &mut ep_out_buffer, usb_config);

    let mut device = embassy_usb::Config::new(USB_VID, USB_PID);
    device.manufacturer = Some("penscape");
    device.product = Some("3D pen base station");
    // The chip's unique ID, so that the host can tell two base stations apart (and a
    // calibration can name the one it belongs to).
    device.serial_number = Some(uid::uid_hex());
    // The budget for the configured receivers (pen_core::board), not a flat 100 mA.
    device.max_power = pen_core::board::usb_current_ma(receivers);
    device.max_packet_size_0 = 64;
    device.supports_remote_wakeup = true;
    // Interface association descriptors for the CDC function in a composite device.
    device.composite_with_iads = true;
    device.device_class = 0xEF;
    device.device_sub_class = 0x02;
    device.device_protocol = 0x01;

    // The OS pen collection spans the saved calibration's display: its logical ranges are the
    // display's size, fixed at enumeration (a new size saved restarts the device).
    let descriptor = report_descriptor(engine.lock(|e| e.borrow().os_extent()));
    // Everything the USB stack borrows is declared before the builder, so it outlives it.
    let mut features = FeatureHandler {
        engine: &engine,
        store: &store,
    };
    let mut bus_state = BusState;
    let mut hid_state = hid::State::new();
    let mut cdc_state = cdc_acm::State::new();
    let mut config_descriptor = [0; 256];
    let mut bos_descriptor = [0; 256];
    let mut msos_descriptor = [0; 0];
    // Feature reports travel over the control pipe: room for the largest (configuration).
    let mut control_buf = [0; 256];
    let mut builder = Builder::new(
        driver,
        device,
        &mut config_descriptor,
        &mut bos_descriptor,
        &mut msos_descriptor,
        &mut control_buf,
    );
    builder.handler(&mut bus_state);
    let hid_config = hid::Config {
        report_descriptor: descriptor.bytes(),
        request_handler: Some(&mut features),
        poll_ms: 1,
        max_packet_size: HID_PACKET as u16,
        hid_subclass: HidSubclass::No,
        hid_boot_protocol: HidBootProtocol::None,
    };
    let hid_writer = HidWriter::<_, HID_PACKET>::new(&mut builder, &mut hid_state, hid_config);
    let cdc = CdcAcmClass::new(&mut builder, &mut cdc_state, 64);
    let (cdc_sender, cdc_receiver, cdc_control) = cdc.split_with_control();
    let mut usb = builder.build();

    let hid_queue = HidQueue::new();
    let serial_queue = SerialQueue::new();

    // The USB device, waking the host when the pen asks to while the bus is suspended.
    let usb_task = async {
        loop {
            usb.run_until_suspend().await;
            // A request raised before this suspend (during the last wakeup, say) is stale: only a
            // press during this suspend wakes the host.
            usb::WAKE_HOST.reset();
            if let Either::Second(()) = select(usb.wait_resume(), usb::WAKE_HOST.wait()).await
                && let Err(e) = usb.remote_wakeup().await
            {
                warn!("remote wakeup refused: {}", e);
            }
        }
    };

    // The measurement loop: one cycle after another, paused while the bus is suspended.
    let sink = BoardSink {
        hid: &hid_queue,
        serial: &serial_queue,
        serial_control: &cdc_control,
    };
    let mut station = Station::new(&engine, ranging, switches, BoardClock, sink);
    let station_task = async {
        let mut next_log = Instant::now();
        let mut wake = WakeOnPress::default();
        let mut was_suspended = false;
        loop {
            watchdog.pet();
            // 12 V only while configured and not suspended; after switching it on, the soft
            // start (24 ms) and the converter's start-up before the next burst.
            let powered = usb::CONFIGURED.load(core::sync::atomic::Ordering::Relaxed)
                && !usb::SUSPENDED.load(core::sync::atomic::Ordering::Relaxed);
            if powered != boost.is_set_high() {
                boost.set_level(Level::from(powered));
                if powered {
                    Timer::after_millis(100).await;
                }
            }
            if usb::SUSPENDED.load(core::sync::atomic::Ordering::Relaxed) {
                // No bursts during suspend; a new press of the tip wakes the host.
                use pen_core::Switches;
                if !was_suspended {
                    wake.suspended();
                    was_suspended = true;
                }
                if wake.sample(station.switches.read()[0]) {
                    usb::WAKE_HOST.signal(());
                }
                Timer::after_millis(10).await;
                continue;
            }
            was_suspended = false;
            station.cycle().await;
            if Instant::now() >= next_log {
                next_log += Duration::from_secs(10);
                let c = engine.lock(|e| e.borrow().counters());
                debug!(
                    "{} dropped HID, {} dropped serial, {} bad frames",
                    usb::DROPPED_HID.load(core::sync::atomic::Ordering::Relaxed),
                    usb::DROPPED_SERIAL.load(core::sync::atomic::Ordering::Relaxed),
                    usb::BAD_FRAMES.load(core::sync::atomic::Ordering::Relaxed)
                );
                info!("{}", c);
                let (used, size) = stack::high_water();
                info!("stack: {} of {} bytes used at most", used, size);
            }
        }
    };

    // Restart into the bootloader, or restart the firmware, once the request's answer has gone
    // out.
    let bootloader_task = async {
        match select(usb::BOOTLOADER.wait(), usb::RESTART.wait()).await {
            Either::First(()) => {
                info!("restarting into the DFU bootloader");
                Timer::after_millis(50).await;
                bootloader::restart_into_bootloader()
            }
            Either::Second(()) => {
                info!("restarting: the saved display size needs a new USB descriptor");
                Timer::after_millis(50).await;
                cortex_m::peripheral::SCB::sys_reset()
            }
        }
    };

    join(
        join3(usb_task, station_task, bootloader_task),
        join3(
            usb::hid_writer(hid_writer, &hid_queue),
            usb::serial_writer(cdc_sender, &cdc_control, &serial_queue),
            usb::serial_reader(cdc_receiver, &engine, &store, &serial_queue),
        ),
    )
    .await;
}
