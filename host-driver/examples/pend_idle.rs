//! Many idle clients on pend's hub (issue 22 item 9): N clients (default 3000) connect through
//! real Unix sockets to a hub serving at most M (default 64, pend's `--max-clients`) while the
//! simulated pen holds still, read their first line and stop reading. Prints how many were
//! greeted and refused, how long that took, and this process's threads and resident memory
//! before, while they stay and after they leave.
//!
//! `cargo run --release -p pen-host --example pend_idle [-- CLIENTS MAX_CLIENTS]`

// The simulated pen is behind the default `sim` feature; this example is not listed with
// `required-features` in Cargo.toml, so without it it says what it needs instead of failing.
#[cfg(not(feature = "sim"))]
fn main() {
    eprintln!("pend_idle needs the sim feature (the default)");
}

#[cfg(feature = "sim")]
fn main() {
    idle::main()
}

#[cfg(feature = "sim")]
mod idle {
    use std::io::{BufRead, BufReader};
    use std::os::unix::net::UnixStream;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    use std::time::{Duration, Instant};

    use pen_host::calibration::{Calibration, DisplaySize};
    use pen_host::daemon::{self, DEFAULT_MAX_CLIENTS, DEFAULT_QUEUE, Hub};
    use pen_host::pipeline::Pipeline;
    use pen_host::source::Source;
    use pen_host::transport::sim::SimOptions;

    /// Threads and resident memory (MB) of this process.
    fn status() -> String {
        let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        let field = |k: &str| {
            s.lines()
                .find_map(|l| l.strip_prefix(k))
                .and_then(|v| v.split_whitespace().next()?.parse::<f64>().ok())
                .unwrap_or(f64::NAN)
        };
        format!(
            "{} threads, {:.1} MB resident",
            field("Threads:"),
            field("VmRSS:") / 1024.0
        )
    }

    pub fn main() {
        let args: Vec<String> = std::env::args().collect();
        let clients: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(3000);
        let max: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(DEFAULT_MAX_CLIENTS);
        let path = std::env::temp_dir().join(format!("pend-idle-{}/pend.sock", std::process::id()));
        let listener = daemon::bind(&path).expect("bind");
        let hub = Arc::new(Hub::new(max));
        let stop = Arc::new(AtomicBool::new(false));
        let (h, s) = (hub.clone(), stop.clone());
        std::thread::spawn(move || daemon::accept(listener, h, DEFAULT_QUEUE, s));
        let (h, s) = (hub.clone(), stop.clone());
        std::thread::spawn(move || {
            let source = Source::Sim(SimOptions {
                scenario: pen_sim::scenarios::by_name("hold").expect("scenario"),
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
        std::thread::sleep(Duration::from_millis(300));
        println!("before: {} (main, acceptor, device)", status());
        let start = Instant::now();
        let streams: Vec<UnixStream> = (0..clients)
            .map(|_| UnixStream::connect(&path).expect("connect"))
            .collect();
        let (mut greeted, mut refused) = (0, 0);
        for s in &streams {
            let _ = s.set_read_timeout(Some(Duration::from_secs(30)));
            let mut line = String::new();
            let _ = BufReader::new(s).read_line(&mut line);
            if line.contains(r#""type":"hello""#) {
                greeted += 1;
            } else if line.contains(r#""type":"refused""#) {
                refused += 1;
            }
        }
        println!(
            "{clients} clients (at most {max} served): {greeted} greeted, {refused} refused in {:.1} s; {}",
            start.elapsed().as_secs_f64(),
            status()
        );
        std::thread::sleep(Duration::from_secs(2));
        println!("idle for 2 s: {}", status());
        drop(streams);
        std::thread::sleep(Duration::from_secs(3));
        println!("3 s after they left: {} ({} clients)", status(), hub.clients());
        let _ = std::fs::remove_file(&path);
    }
}
