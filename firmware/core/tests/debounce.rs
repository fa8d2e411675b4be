//! The debouncer: bounce never produces an extra press, and no press is missed.

use pen_core::debounce::Debouncer;
use proptest::prelude::*;

const DEBOUNCE_US: u64 = 5_000;
const SAMPLE_US: u64 = 500;

/// A switch's raw level over time: presses with bouncing edges.
#[derive(Debug, Clone)]
struct Press {
    /// When the contact first closes, µs after the previous release settled.
    gap_us: u64,
    /// How long it is held after the closing bounce settles, µs.
    hold_us: u64,
    /// Bounce at each edge: alternating level changes within the bounce time.
    bounce_in: Vec<u64>,
    bounce_out: Vec<u64>,
}

/// Bounce patterns: up to 8 chatters spread over less than the debounce time.
fn bounce() -> impl Strategy<Value = Vec<u64>> {
    proptest::collection::vec(50u64..600, 0..8).prop_map(|mut v| {
        // Keep the total under the debounce time minus one sample, as contact bounce does.
        let mut total = 0;
        v.retain(|d| {
            total += d;
            total < DEBOUNCE_US - SAMPLE_US
        });
        v
    })
}

fn press() -> impl Strategy<Value = Press> {
    (
        DEBOUNCE_US + 1_000..60_000u64,
        DEBOUNCE_US + 1_000..200_000u64,
        bounce(),
        bounce(),
    )
        .prop_map(|(gap_us, hold_us, bounce_in, bounce_out)| Press {
            gap_us,
            hold_us,
            bounce_in,
            bounce_out,
        })
}

/// The raw level at each time: a list of (time, level) edges.
fn edges(presses: &[Press]) -> Vec<(u64, bool)> {
    let mut out = Vec::new();
    let mut t = 0;
    for p in presses {
        t += p.gap_us;
        let mut level = true;
        out.push((t, level));
        for d in &p.bounce_in {
            t += d;
            level = !level;
            out.push((t, level));
        }
        if !level {
            out.push((t + 1, true));
        }
        t += p.hold_us;
        let mut level = false;
        out.push((t, level));
        for d in &p.bounce_out {
            t += d;
            level = !level;
            out.push((t, level));
        }
        if level {
            out.push((t + 1, false));
        }
    }
    out.push((t + 20_000, false));
    out
}

proptest! {
    #[test]
    fn one_transition_per_edge(presses in proptest::collection::vec(press(), 1..6), phase in 0..SAMPLE_US) {
        let edges = edges(&presses);
        let end = edges.last().map_or(0, |e| e.0);
        let mut d = Debouncer::new();
        let (mut level, mut next_edge) = (false, 0);
        let (mut presses_seen, mut releases_seen) = (0, 0);
        let mut t = phase;
        while t <= end {
            while next_edge < edges.len() && edges[next_edge].0 <= t {
                level = edges[next_edge].1;
                next_edge += 1;
            }
            let changed = d.sample(t, [level, false, false], DEBOUNCE_US);
            if changed[0] {
                if d.state()[0] { presses_seen += 1 } else { releases_seen += 1 }
            }
            prop_assert!(!changed[1] && !changed[2]);
            t += SAMPLE_US;
        }
        prop_assert_eq!(presses_seen, presses.len(), "presses");
        prop_assert_eq!(releases_seen, presses.len(), "releases");
    }
}

#[test]
fn a_press_is_taken_at_its_first_edge() {
    let mut d = Debouncer::new();
    assert_eq!(d.sample(0, [false; 3], DEBOUNCE_US), [false; 3]);
    assert_eq!(d.sample(500, [true, false, false], DEBOUNCE_US), [true, false, false]);
    // Bounce within the hold-off is ignored…
    assert_eq!(d.sample(1000, [false, false, false], DEBOUNCE_US), [false; 3]);
    assert_eq!(d.state(), [true, false, false]);
    // …and a release during it is taken when it ends: a short click is never lost.
    assert_eq!(d.sample(5500, [false, false, false], DEBOUNCE_US), [true, false, false]);
    assert_eq!(d.state(), [false; 3]);
}
