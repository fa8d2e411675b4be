//! Firmware of the pen's base station (STM32F411CE "Black Pill").
//!
//! This first image brings up the USB HID pen interface with the protocol crate's report
//! descriptor, answers the device-information feature report, and sends a pen report per cycle
//! marked out of range. Tracking (ultrasonic capture, solving, filtering, switches) and the
//! CDC-ACM serial link arrive with the firmware issue; the wiring here stays as it is: clocks,
//! interrupts, driver, builder, classes, join.
#![no_std]
#![no_main]

use defmt::{info, warn};
use embassy_executor::Spawner;
use embassy_futures::join::join;
use embassy_stm32::time::Hertz;
use embassy_stm32::usb::{self, Driver};
use embassy_stm32::{Config, bind_interrupts, peripherals, uid};
use embassy_time::{Duration, Instant, Ticker};
use embassy_usb::Builder;
use embassy_usb::class::hid::{self, HidBootProtocol, HidSubclass, HidWriter, ReportId as HidReportId, RequestHandler};
use embassy_usb::control::OutResponse;
use pen_protocol::{
    DeviceInfo, FirmwareVersion, MAX_RECEIVERS, PROTOCOL_VERSION, PenReport, Position, Quality, REPORT_DESCRIPTOR,
    Report, Status, StatusCode, USB_PID, USB_VID,
};
use {defmt_rtt as _, panic_probe as _};

bind_interrupts!(struct Irqs {
    OTG_FS => usb::InterruptHandler<peripherals::USB_OTG_FS>;
});

/// Cycles per second of this image's report loop.
const CYCLE_HZ: u16 = 100;

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

/// Answers the host's feature-report requests.
struct Features {
    info: DeviceInfo,
    status: Status,
}

impl RequestHandler for Features {
    fn get_report(&mut self, id: HidReportId, buf: &mut [u8]) -> Option<usize> {
        match id {
            HidReportId::Feature(id) if id == DeviceInfo::ID as u8 => self.info.encode(buf).ok(),
            HidReportId::Feature(id) if id == Status::ID as u8 => self.status.encode(buf).ok(),
            _ => None,
        }
    }

    fn set_report(&mut self, id: HidReportId, _data: &[u8]) -> OutResponse {
        // Configuration and commands arrive with the firmware issue; until then every write is
        // refused and the status report says so.
        let request = match id {
            HidReportId::Feature(id) | HidReportId::Out(id) | HidReportId::In(id) => id,
        };
        self.status = Status::failed(request, StatusCode::Unsupported);
        OutResponse::Rejected
    }
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    // Clocks: 25 MHz crystal → PLL: 96 MHz system clock and the 48 MHz USB clock.
    let mut config = Config::default();
    {
        use embassy_stm32::rcc::*;
        config.rcc.hse = Some(Hse {
            freq: Hertz(25_000_000),
            mode: HseMode::Oscillator,
        });
        config.rcc.pll_src = PllSource::HSE;
        config.rcc.pll = Some(Pll {
            prediv: PllPreDiv::DIV25,
            mul: PllMul::MUL192,
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
    info!("pen base station, firmware {}, protocol {}", FIRMWARE, PROTOCOL_VERSION);

    // USB driver. The Black Pill has no VBUS sense wired, so VBUS detection stays off.
    let mut ep_out_buffer = [0u8; 256];
    let mut usb_config = usb::Config::default();
    usb_config.vbus_detection = false;
    let driver = Driver::new_fs(p.USB_OTG_FS, Irqs, p.PA12, p.PA11, &mut ep_out_buffer, usb_config);

    let mut device = embassy_usb::Config::new(USB_VID, USB_PID);
    device.manufacturer = Some("penscape");
    device.product = Some("3D pen base station");
    device.serial_number = None;
    device.max_power = 100;
    device.max_packet_size_0 = 64;

    // Everything the USB stack borrows is declared before the builder, so it outlives it.
    let mut features = Features {
        info: DeviceInfo {
            protocol: PROTOCOL_VERSION,
            firmware: FIRMWARE,
            receiver_count: 0,
            max_receivers: MAX_RECEIVERS as u8,
            fix_rate_hz: CYCLE_HZ,
            unique_id: uid::uid(),
        },
        status: Status::ok(0),
    };
    let mut hid_state = hid::State::new();
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

    let hid_config = hid::Config {
        report_descriptor: &REPORT_DESCRIPTOR,
        request_handler: Some(&mut features),
        poll_ms: 1,
        max_packet_size: 64,
        hid_subclass: HidSubclass::No,
        hid_boot_protocol: HidBootProtocol::None,
    };
    let mut writer = HidWriter::<_, 64>::new(&mut builder, &mut hid_state, hid_config);

    let mut usb = builder.build();

    let reports = async {
        let mut ticker = Ticker::every(Duration::from_hz(CYCLE_HZ as u64));
        let mut seq: u16 = 0;
        loop {
            ticker.next().await;
            let report = PenReport {
                sw1: false,
                sw2: false,
                sw3: false,
                in_range: false,
                display_frame: false,
                position: Position::default(),
                seq,
                // The device clock in µs, wrapping as the protocol defines.
                timestamp_us: Instant::now().as_micros() as u32,
                quality: Quality::NONE,
            };
            if let Err(e) = writer.write_serialize(&report).await {
                warn!("pen report not sent: {}", e);
            }
            seq = seq.wrapping_add(1);
        }
    };

    join(usb.run(), reports).await;
}
