//! Digests of processed rivers, to show that a change to the river code keeps their shapes bit
//! for bit: run it before and after and compare the lines.
//!
//! Per river: the mask's digest, the whole shape's (mask, lakes, necks, line, levels, turns, the
//! nearest-sample field, history), the next year's preview's, and, for the bench's rivers, the
//! drag previews of control points 19 and 20 moved as in the bench.
//!
//! Run: `cargo run --release -p penmodel-terrain --example river_digest [omega.json]` (the
//! document's first river is added at 5, 12 and 20 years; default
//! `modeler/examples/rivers/omega.json`).
//!
//! `river_digest --drag N [YEARS]` instead runs the river bench's `drag/512/YEARS` preview (10
//! years unless given) N times (for `valgrind --tool=callgrind`: the difference of two counts is
//! the cost of the extra calls).

use penmodel_terrain::river::{self, Constants, Shape, drag};
use penmodel_terrain::{Document, Grid, River};

/// FNV-1a over bytes: stable across builds and Rust versions.
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ u64::from(x)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

fn digest(b: &[u8]) -> u64 {
    let mut h = Fnv::new();
    h.bytes(b);
    h.0
}

fn shape_digest(s: &Shape) -> u64 {
    let mut h = Fnv::new();
    h.bytes(format!("{:?}", s.window).as_bytes());
    h.bytes(&s.mask);
    for l in &s.lakes {
        h.bytes(&l.to_le_bytes());
    }
    // Debug prints floats as their shortest round trip: the same text is the same bits.
    h.bytes(format!("{:?}{:?}{:?}{:?}{:?}", s.necks, s.line, s.levels, s.turns, s.history).as_bytes());
    for o in &s.near.owner {
        h.bytes(&o.to_le_bytes());
    }
    for d in &s.near.dist {
        h.bytes(&d.to_bits().to_le_bytes());
    }
    for &v in &s.near.side {
        h.bytes(&[v as u8]);
    }
    h.0
}

fn cells_digest(c: &drag::Cells) -> u64 {
    digest(format!("{:?}", c).as_bytes())
}

fn grid(n: u32) -> Grid {
    Grid {
        cols: n,
        rows: n,
        cell_size: 1.0,
    }
}

/// The bench's `drag/512/YEARS` preview `calls` times.
fn drag_calls(calls: usize, years: u32) {
    let c = Constants::default();
    let rv = river::meander(512, 14, 4.0, years);
    let d = drag::Drag::new(&rv, 20, &grid(512), &c);
    let mut moved = rv.clone();
    moved.points[20] = [moved.points[20][0] + 6.0, moved.points[20][1] - 4.0];
    let mut cells = 0;
    for _ in 0..calls {
        let p = d.preview(std::hint::black_box(&moved));
        cells += p.erosion.len() + p.deposition.len();
    }
    println!("{calls} calls, {cells} cells");
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).is_some_and(|a| a == "--drag") {
        let calls = args.get(2).ok_or("--drag needs a count")?.parse()?;
        let years = args.get(3).map_or(Ok(10), |y| y.parse())?;
        drag_calls(calls, years);
        return Ok(());
    }
    let path = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "modeler/examples/rivers/omega.json".to_string());
    let doc = Document::load(std::path::Path::new(&path))?;
    let omega = doc.rivers.first().ok_or("the document has no river")?;
    let mut rivers: Vec<(String, River, Grid, bool)> = Vec::new();
    for (size, anchors, width, years) in [
        (128, 6, 1.0, 20),
        (256, 8, 3.0, 5),
        (256, 8, 3.0, 20),
        (512, 14, 4.0, 0),
        (512, 14, 4.0, 3),
        (512, 14, 4.0, 10),
        (512, 14, 4.0, 20),
        (512, 14, 6.0, 20),
        (1024, 14, 6.0, 1),
        (1024, 14, 8.0, 5),
    ] {
        let bench = size == 512 && width == 4.0 && years <= 10;
        rivers.push((
            format!("meander({size}, {anchors}, {width} m, {years})"),
            river::meander(size, anchors, width, years),
            grid(size),
            bench,
        ));
    }
    for years in [5, 12, 20] {
        rivers.push((
            format!("{path}[0], {years} years"),
            River {
                iterations: years,
                ..omega.clone()
            },
            doc.grid,
            false,
        ));
    }
    let c = Constants::default();
    for (name, rv, g, bench) in &rivers {
        let s = Shape::process(rv, g, &c);
        let p = s.preview();
        let mut pv = p.erosion.clone();
        pv.extend(&p.deposition);
        print!(
            "{name}: mask {:016x} shape {:016x} preview {:016x}",
            digest(&s.mask),
            shape_digest(&s),
            digest(&pv)
        );
        if *bench {
            for point in [19, 20] {
                let d = drag::Drag::new(rv, point, g, &c);
                let mut moved = rv.clone();
                moved.points[point] = [moved.points[point][0] + 6.0, moved.points[point][1] - 4.0];
                print!(" drag{point} {:016x}", cells_digest(&d.preview(&moved)));
            }
        }
        println!();
    }
    Ok(())
}
