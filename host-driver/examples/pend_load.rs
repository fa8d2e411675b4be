//! Load on pend's fan-out: N clients (default 32) reading events from the simulated pen at
//! 1 kHz for S seconds (default 10), in this process, through real Unix sockets. Prints each
//! figure the daemon's targets name: events per second, events each client missed, and the
//! latency from a report's arrival at the host to a client's read.
//!
//! `cargo run --release -p pen-host --example pend_load [-- CLIENTS SECONDS]`

use std::io::{BufRead, BufReader};
use std::os::unix::net::UnixStream;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use pen_host::calibration::{Calibration, DisplaySize};
use pen_host::client::{Line, parse_line};
use pen_host::daemon::{self, DEFAULT_QUEUE, Hub};
use pen_host::events::EventKind;
use pen_host::pipeline::Pipeline;
use pen_host::sample::now_us;
use pen_host::source::Source;
use pen_host::transport::sim::SimOptions;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let clients: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(32);
    let seconds: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(10.0);
    let path = std::env::temp_dir().join(format!("pend-load-{}/pend.sock", std::process::id()));
    let listener = daemon::bind(&path).expect("bind");
    let hub = Arc::new(Hub::default());
    let stop = Arc::new(AtomicBool::new(false));
    let (h, s) = (hub.clone(), stop.clone());
    std::thread::spawn(move || daemon::accept(listener, h, DEFAULT_QUEUE, s));
    let streams: Vec<UnixStream> = (0..clients)
        .map(|_| UnixStream::connect(&path).expect("connect"))
        .collect();
    while hub.clients() < clients {
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut scenario = pen_sim::scenarios::by_name("hand-sweep").expect("scenario");
    scenario.config.report_rate_hz = 1000;
    let (h, s) = (hub.clone(), stop.clone());
    std::thread::spawn(move || {
        let source = Source::Sim(SimOptions {
            scenario,
            seed: 1,
            speed: 1.0,
            plug: Default::default(),
        });
        daemon::run_device(
            Pipeline::new(source, Calibration::identity(DisplaySize::REFERENCE)),
            h,
            s,
            |_| {},
        )
    });
    let until = Instant::now() + Duration::from_secs_f64(seconds);
    let readers: Vec<_> = streams
        .into_iter()
        .map(|stream| {
            std::thread::spawn(move || {
                let _ = stream.set_read_timeout(Some(Duration::from_millis(200)));
                let mut r = BufReader::new(stream);
                let (mut events, mut missed, mut lat) = (0u64, 0u64, Vec::new());
                let mut line = String::new();
                while Instant::now() < until {
                    line.clear();
                    if r.read_line(&mut line).unwrap_or(0) == 0 {
                        continue;
                    }
                    let now = now_us();
                    if let Ok(Line::Event(e)) = parse_line(line.trim_end()) {
                        events += 1;
                        match e.kind {
                            EventKind::Missed { count } => missed += count,
                            EventKind::Motion => lat.push(now.saturating_sub(e.t_us)),
                            _ => {}
                        }
                    }
                }
                (events, missed, lat)
            })
        })
        .collect();
    let results: Vec<(u64, u64, Vec<u64>)> = readers.into_iter().map(|r| r.join().expect("reader")).collect();
    let total: u64 = results.iter().map(|r| r.0).sum();
    let missed: u64 = results.iter().map(|r| r.1).sum();
    let mut lat: Vec<u64> = results.into_iter().flat_map(|r| r.2).collect();
    lat.sort_unstable();
    let pct = |p: f64| lat.get(((lat.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(0);
    println!(
        "{clients} clients, {seconds} s: {total} events delivered ({:.0}/s in all, {:.0}/s per client), {missed} missed",
        total as f64 / seconds,
        total as f64 / seconds / clients as f64
    );
    println!(
        "latency from report arrival to client read: p50 {} µs, p99 {} µs, max {} µs",
        pct(0.5),
        pct(0.99),
        pct(1.0)
    );
    let _ = std::fs::remove_file(&path);
}
