//! The bench rig: a Raspberry Pi Pico in place of the pen's acoustics.
//!
//! The base station's burst pin (PA8) comes in on GP2 (and GP3, jumpered to it: each PIO block
//! needs the pin in its own pin mapping). Eight PIO state machines, one per receiver input, wait
//! for a burst's first rising edge and play the pulses the host asked for on their receiver
//! line (up to three per burst: pickup, the arrival, an echo), in 8 ns steps; the switch lines SW1–SW3 are pulled low (pressed) or let go (released).
//! The host sends one cycle per burst over USB serial (pen-rig-proto's messages); after each
//! burst the rig hands the state machines the next cycle's words, so a cycle is always waiting
//! in the FIFOs when its burst comes. Pins and wiring: docs/hil-rig.md.
#![no_std]
#![no_main]

use core::cell::{Cell, RefCell};

use defmt::{info, warn};
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_futures::join::join3;
use embassy_rp::bind_interrupts;
use embassy_rp::gpio::{Flex, Level, Pull};
use embassy_rp::peripherals::{PIO0, PIO1, USB};
use embassy_rp::pio::{
    self, Direction, FifoJoin, Instance, LoadedProgram, Pio, ShiftConfig, ShiftDirection, StateMachine,
};
use embassy_rp::usb::{self, Driver};
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::channel::Channel;
use embassy_usb::class::cdc_acm::{CdcAcmClass, State};
use embassy_usb::driver::EndpointError;
use embassy_usb::{Builder, Config};
use panic_probe as _;
use pen_rig_proto::message::SWITCH_MASK;
use pen_rig_proto::schedule::MAX_WORDS;
use pen_rig_proto::schedule::PIO_HZ;
use pen_rig_proto::{
    ErrorCode, FrameDecoder, HostMessage, Info, MAX_FRAME, MAX_MESSAGE, RECEIVERS, RIG_PID, RIG_PRODUCT,
    RIG_PROTOCOL_VERSION, RIG_VID, RigMessage, RigStatus, encode_frame, words,
};

bind_interrupts!(struct Irqs {
    USBCTRL_IRQ => usb::InterruptHandler<USB>;
    PIO0_IRQ_0 => pio::InterruptHandler<PIO0>;
    PIO1_IRQ_0 => pio::InterruptHandler<PIO1>;
});

/// Cycles the rig holds: at the base station's ~150 cycles/s, 0.4 s of slack for the host.
const QUEUE: usize = 64;

/// One cycle, ready for the state machines: per receiver its count word and edge words, and
/// how many of them are used.
struct Queued {
    seq: u32,
    switches: u8,
    words: [([u32; MAX_WORDS], usize); RECEIVERS],
}

/// The receiver program, the same on every state machine. IN and JMP pin: the burst; SET pin:
/// the receiver line. The cycle counts matter: pen-rig-proto's `schedule` relies on them
/// (`FIRST_LATENCY_CYCLES`, `GAP_LATENCY_CYCLES`, the delay and hold loops) — change both
/// together. Per burst it takes a count word, then that many edge words (delay, length).
fn receiver_program() -> pio::program::Program<32> {
    pio::program::pio_asm!(
        ".wrap_target",
        // A burst is 8 periods of 40 kHz: only a rising edge after ~50 µs of quiet starts a
        // cycle (6 cycles × 32 × 32 ≈ 6 200 cycles), so the burst's later edges never do.
        "rearm:",
        "    set x, 31",
        "outer:",
        "    set y, 31",
        "inner:",
        "    jmp pin rearm",
        "    jmp y-- inner [4]",
        "    jmp x-- outer",
        // What `pull noblock` gives when the FIFO is empty: a count of 0, no pulse.
        "    set x, 0",
        "    wait 1 pin 0",
        "    pull noblock",
        // Tells the CPU the count words are taken: time to queue the next cycle's words
        // behind this cycle's edge words (the joined FIFO holds both).
        "    irq nowait 0",
        "    out y, 32",
        "count:",
        "    jmp y-- edge",
        "    jmp rearm",
        "edge:",
        // The hold loop needs y: the pulses still to play wait in the unused ISR.
        "    mov isr, y",
        // Blocking: the CPU queued this cycle's words whole before its burst, so this never
        // waits; were one missing, waiting keeps the words in step rather than playing 0.
        "    pull block",
        "    out x, 22",
        "delay:",
        "    jmp x-- delay",
        "    set pins, 1",
        "    out y, 10",
        "hold:",
        "    jmp y-- hold [31]",
        "    set pins, 0",
        "    mov y, isr",
        "    jmp count",
        ".wrap",
    )
    .program
}

/// Configures state machine `SM` to drive `rx` from the bursts on `burst`, and starts it.
fn start<'d, P: Instance, const SM: usize>(
    sm: &mut StateMachine<'d, P, SM>,
    program: &LoadedProgram<'d, P>,
    burst: &pio::Pin<'d, P>,
    rx: &pio::Pin<'d, P>,
) {
    let mut cfg = pio::Config::default();
    cfg.use_program(program, &[]);
    cfg.set_in_pins(&[burst]);
    cfg.set_jmp_pin(burst);
    cfg.set_set_pins(&[rx]);
    // A cycle is up to four words and the next cycle's are queued while this one's pulses play:
    // eight words, the TX FIFO joined with the unused RX FIFO.
    cfg.fifo_join = FifoJoin::TxOnly;
    // The words' fields come out least significant first: delay, then pulse length.
    cfg.shift_out = ShiftConfig {
        threshold: 32,
        direction: ShiftDirection::Right,
        auto_fill: false,
    };
    // Full speed: one instruction per system clock, 8 ns (the default divider, stated).
    cfg.clock_divider = 1u8.into();
    sm.set_config(&cfg);
    // A comparator output at rest: low.
    sm.set_pins(Level::Low, &[rx]);
    sm.set_pin_dirs(Direction::Out, &[rx]);
    sm.set_enable(true);
}

/// Queues one cycle's words (count word first) for a state machine that has just taken the
/// last cycle's count word; false if its FIFO was full (it did not take its words: the burst
/// input is stuck or miswired, or the host let a pulse run into the next burst).
fn hand<P: Instance, const SM: usize>(
    sm: &mut StateMachine<'_, P, SM>,
    (words, len): &([u32; MAX_WORDS], usize),
) -> bool {
    words.iter().take(*len).all(|&w| sm.tx().try_push(w))
}

/// A switch line: pressed pulls it low; released lets the base station's pull-up have it, as
/// the pen's switch to ground does (never driven high, so the two boards never fight).
fn set_switch(line: &mut Flex<'_>, pressed: bool) {
    if pressed {
        line.set_low();
        line.set_as_output();
    } else {
        line.set_as_input();
    }
}

/// Sets SW1–SW3 from bits as the reports carry them (SW1 = 1, SW2 = 2, SW3 = 4).
fn set_switches(lines: &RefCell<[Flex<'_>; 3]>, bits: u8) {
    for (i, line) in lines.borrow_mut().iter_mut().enumerate() {
        set_switch(line, bits & 1 << i != 0);
    }
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_rp::init(Default::default());
    info!(
        "bench rig: {} receivers, {} ns steps",
        RECEIVERS,
        1_000_000_000 / PIO_HZ
    );

    // Receivers 0–3 on PIO0 (GP6–GP9, burst on GP2), 4–7 on PIO1 (GP10–GP13, burst on GP3).
    let Pio {
        mut common,
        irq0: mut burst_irq,
        mut sm0,
        mut sm1,
        mut sm2,
        mut sm3,
        ..
    } = Pio::new(p.PIO0, Irqs);
    let Pio {
        common: mut common1,
        sm0: mut sm4,
        sm1: mut sm5,
        sm2: mut sm6,
        sm3: mut sm7,
        ..
    } = Pio::new(p.PIO1, Irqs);
    let program = receiver_program();
    let loaded = common.load_program(&program);
    let loaded1 = common1.load_program(&program);
    let mut burst = common.make_pio_pin(p.PIN_2);
    let mut burst1 = common1.make_pio_pin(p.PIN_3);
    // An unconnected burst wire reads as no burst rather than as noise.
    burst.set_pull(Pull::Down);
    burst1.set_pull(Pull::Down);
    let rx = [
        common.make_pio_pin(p.PIN_6),
        common.make_pio_pin(p.PIN_7),
        common.make_pio_pin(p.PIN_8),
        common.make_pio_pin(p.PIN_9),
    ];
    let rx1 = [
        common1.make_pio_pin(p.PIN_10),
        common1.make_pio_pin(p.PIN_11),
        common1.make_pio_pin(p.PIN_12),
        common1.make_pio_pin(p.PIN_13),
    ];
    start(&mut sm0, &loaded, &burst, &rx[0]);
    start(&mut sm1, &loaded, &burst, &rx[1]);
    start(&mut sm2, &loaded, &burst, &rx[2]);
    start(&mut sm3, &loaded, &burst, &rx[3]);
    start(&mut sm4, &loaded1, &burst1, &rx1[0]);
    start(&mut sm5, &loaded1, &burst1, &rx1[1]);
    start(&mut sm6, &loaded1, &burst1, &rx1[2]);
    start(&mut sm7, &loaded1, &burst1, &rx1[3]);

    // SW1–SW3 on GP18–GP20, released at start. Shared: the player sets them with each cycle,
    // the link at once (suspend and wake happen without bursts).
    let switches = RefCell::new([Flex::new(p.PIN_18), Flex::new(p.PIN_19), Flex::new(p.PIN_20)]);
    set_switches(&switches, 0);

    // USB: one CDC-ACM function, the host's link.
    let driver = Driver::new(p.USB, Irqs);
    let mut device = Config::new(RIG_VID, RIG_PID);
    device.manufacturer = Some("penscape");
    device.product = Some(RIG_PRODUCT);
    device.max_power = 100;
    device.max_packet_size_0 = 64;
    let mut config_descriptor = [0; 256];
    let mut bos_descriptor = [0; 256];
    let mut control_buf = [0; 64];
    let mut cdc_state = State::new();
    let mut builder = Builder::new(
        driver,
        device,
        &mut config_descriptor,
        &mut bos_descriptor,
        &mut [],
        &mut control_buf,
    );
    let mut cdc = CdcAcmClass::new(&mut builder, &mut cdc_state, 64);
    let mut usb = builder.build();

    // Everything below runs on this one executor: plain cells, no locks.
    let queue = Channel::<NoopRawMutex, Queued, QUEUE>::new();
    let status = Cell::new(RigStatus::default());
    // Set by Stop, taken by the player at the next burst.
    let stop = Cell::new(false);

    let player = async {
        // The cycle whose words the state machines hold for the next burst.
        let mut pending: Option<(u32, u8)> = None;
        loop {
            burst_irq.wait().await;
            let mut s = status.get();
            s.bursts = s.bursts.wrapping_add(1);
            // Stop emptied the queue and the counters; the cycle already handed over has just
            // played at this burst, and is not counted.
            if stop.take() {
                pending = None;
            }
            match pending.take() {
                // This burst played it.
                Some((seq, bits)) => {
                    set_switches(&switches, bits);
                    s.played = s.played.wrapping_add(1);
                    s.last_played = seq;
                }
                // The host fell behind (counted once it has started playing).
                None if s.played > 0 => s.underruns = s.underruns.wrapping_add(1),
                None => {}
            }
            if let Ok(next) = queue.try_receive() {
                let w = &next.words;
                let taken = hand(&mut sm0, &w[0])
                    & hand(&mut sm1, &w[1])
                    & hand(&mut sm2, &w[2])
                    & hand(&mut sm3, &w[3])
                    & hand(&mut sm4, &w[4])
                    & hand(&mut sm5, &w[5])
                    & hand(&mut sm6, &w[6])
                    & hand(&mut sm7, &w[7]);
                if !taken {
                    warn!(
                        "a state machine's FIFO was full: is GP3 jumpered to GP2, or did a pulse run into the next burst?"
                    );
                }
                pending = Some((next.seq, next.switches));
            }
            s.queued = queue.len() as u16;
            status.set(s);
        }
    };

    let link = async {
        loop {
            cdc.wait_connection().await;
            info!("host connected");
            let mut decoder = FrameDecoder::new();
            let mut packet = [0u8; 64];
            'connected: loop {
                let n = match cdc.read_packet(&mut packet).await {
                    Ok(n) => n,
                    Err(EndpointError::Disabled) => break 'connected,
                    Err(EndpointError::BufferOverflow) => continue,
                };
                for &byte in &packet[..n] {
                    let answer = match decoder.push(byte) {
                        None => continue,
                        Some(Err(_)) => RigMessage::Error(ErrorCode::Malformed),
                        Some(Ok(payload)) => match HostMessage::decode(payload) {
                            Err(_) => RigMessage::Error(ErrorCode::Malformed),
                            Ok(m) => handle(m, &queue, &status, &stop, &switches),
                        },
                    };
                    if let RigMessage::Error(ErrorCode::Malformed) = answer {
                        let mut s = status.get();
                        s.bad_frames = s.bad_frames.wrapping_add(1);
                        status.set(s);
                    }
                    let mut payload = [0u8; MAX_MESSAGE];
                    let len = answer.encode(&mut payload);
                    let mut frame = [0u8; MAX_FRAME];
                    // Every answer fits a frame and a frame fits one 64-byte packet (the
                    // largest answer frames to 30 bytes), so no zero-length packet is needed.
                    let Ok(len) = encode_frame(&payload[..len], &mut frame) else {
                        continue;
                    };
                    if cdc.write_packet(&frame[..len]).await.is_err() {
                        break 'connected;
                    }
                }
            }
            info!("host gone");
        }
    };

    join3(usb.run(), player, link).await;
}

/// Acts on one message from the host; returns the answer.
fn handle(
    message: HostMessage,
    queue: &Channel<NoopRawMutex, Queued, QUEUE>,
    status: &Cell<RigStatus>,
    stop: &Cell<bool>,
    switches: &RefCell<[Flex<'_>; 3]>,
) -> RigMessage {
    match message {
        HostMessage::Hello => {
            return RigMessage::Info(Info {
                version: RIG_PROTOCOL_VERSION,
                receivers: RECEIVERS as u8,
                pio_hz: PIO_HZ,
                queue_capacity: QUEUE as u16,
            });
        }
        HostMessage::Cycle {
            seq, switches, edges, ..
        } => {
            let mut all = [([0; MAX_WORDS], 1); RECEIVERS];
            for (w, e) in all.iter_mut().zip(&edges) {
                match words(e) {
                    Ok(x) => *w = x,
                    Err(_) => return RigMessage::Error(ErrorCode::Unplayable),
                }
            }
            let cycle = Queued {
                seq,
                switches: switches & SWITCH_MASK,
                words: all,
            };
            if queue.try_send(cycle).is_err() {
                return RigMessage::Error(ErrorCode::QueueFull);
            }
        }
        // At once; the next cycle played sets them again from its own bits.
        HostMessage::Switches(bits) => set_switches(switches, bits),
        HostMessage::Stop => {
            while queue.try_receive().is_ok() {}
            set_switches(switches, 0);
            stop.set(true);
            let s = status.get();
            status.set(RigStatus {
                bursts: s.bursts,
                bad_frames: s.bad_frames,
                ..RigStatus::default()
            });
        }
        HostMessage::Status => {}
    }
    let mut s = status.get();
    s.queued = queue.len() as u16;
    RigMessage::Status(s)
}
