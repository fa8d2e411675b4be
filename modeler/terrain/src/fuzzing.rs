//! The properties the fuzz targets (`modeler/terrain/fuzz/`) check, in one place so that the
//! stable test that replays their corpora (`tests/fuzz_corpus.rs`) checks exactly the same
//! thing. Not part of the crate's API: hidden, and free to change with the targets.

use std::fs;
use std::path::PathBuf;

use crate::TerrainEngine;
use crate::document::{BaseHeights, Document};
use crate::editor::Editor;
use crate::journal;
use crate::ridge::rain;
use crate::ridge::sun::{self, Field, Sun};
use crate::validate;

/// Any bytes as a document file (any version): never a panic, and a document that loads is
/// valid, and saves as text that loads to the same document and saves to the same text; and,
/// on a small grid ([`TERRAIN_CELLS`], [`TERRAIN_WORK`]), its terrain builds with a finite height
/// in every cell.
pub fn document(bytes: &[u8]) {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return;
    };
    let Ok(doc) = Document::from_json(text) else {
        return;
    };
    check_document(&doc, "the document read");
    check_terrain(&doc);
}

/// The most cells of a document whose terrain the document target builds: 64 × 64.
pub const TERRAIN_CELLS: usize = 4096;

/// The most cell-steps (cells × (1 + thermal iterations + fluvial steps)) of a terrain the
/// document target builds, so that an execution stays within milliseconds.
pub const TERRAIN_WORK: usize = 1 << 20;

/// Builds the terrain of a valid document on a small grid: it must build, one finite height a
/// cell. A base heightmap (`terrain.base`) names a file that is not read here: it gets heights
/// made from the grid (a slope), so that the base's path through the engine runs too.
fn check_terrain(doc: &Document) {
    let cells = doc.grid.cells();
    let erosion = doc.terrain.erosion.as_ref();
    let steps = erosion.map_or(0, |e| e.iterations as usize)
        + erosion.and_then(|e| e.fluvial.as_ref()).map_or(0, |f| f.steps as usize);
    if cells > TERRAIN_CELLS || cells.saturating_mul(1 + steps) > TERRAIN_WORK {
        return;
    }
    let mut doc = doc.clone();
    if let Some(base) = &mut doc.terrain.base
        && base.heights.get().is_none()
    {
        let cols = doc.grid.cols as usize;
        base.heights = BaseHeights::new((0..cells).map(|i| (i % cols + i / cols) as f32 * 0.5).collect());
    }
    let engine = match TerrainEngine::new(&doc) {
        Ok(engine) => engine,
        Err(e) => panic!("a valid document's terrain does not build: {e}"),
    };
    let map = engine.heightmap();
    assert_eq!(map.heights().len(), cells, "the terrain has not one height a cell");
    if let Some(i) = map.heights().iter().position(|h| !h.is_finite()) {
        panic!("the terrain's height at cell {i} is {}", map.heights()[i]);
    }
}

fn check_document(doc: &Document, what: &str) {
    if let Err(e) = validate::document(doc) {
        panic!("{what} is not valid: {e}");
    }
    let saved = doc.to_json();
    let again = match Document::from_json(&saved) {
        Ok(again) => again,
        Err(e) => panic!("{what} saves as text that does not load: {e}\n{saved}"),
    };
    assert_eq!(&again, doc, "{what} loads back different");
    assert_eq!(again.to_json(), saved, "save → load → save is not a fixed point");
}

/// The document the journal target edits: small, so that an execution stays cheap.
pub const JOURNAL_BASE: &str = include_str!("../../examples/04-volcano.json");

/// The journal's first line for [`JOURNAL_BASE`] in version 1 (no sequence numbers, no
/// checksums): the fuzzed bytes follow it, so that the fuzzer need not guess the document's
/// fingerprint to get past the first line.
pub fn journal_open_line() -> String {
    format!(
        "{{\"op\":\"open\",\"journal\":1,\"base\":\"{}\"}}\n",
        journal::fingerprint(JOURNAL_BASE.as_bytes())
    )
}

/// The same first line in version 2, as the editor writes it: `{"seq":1,"crc32":…,"op":"open",…}`.
pub fn journal_open_line_v2() -> String {
    let open = journal::Entry::Open {
        journal: journal::JOURNAL_VERSION,
        base: journal::fingerprint(JOURNAL_BASE.as_bytes()),
    };
    String::from_utf8(journal::line(&open, journal::JOURNAL_VERSION, 1)).unwrap_or_default()
}

/// Any bytes as the journal of [`JOURNAL_BASE`] after its `open` line — a version-2 one when the
/// bytes begin as a version-2 line does (`{"seq":`), else a version-1 one — opened (read-only)
/// as `penmodel open` does after a crash: never a panic; if it opens, the edited document is
/// valid and saves and loads like any other; and the same files open to the same document
/// again. Then opened recovering (`penmodel open --recover`): that always opens, since the
/// `open` line is good; to the same document as the plain open when that opened, with nothing
/// left out, and otherwise to a valid document.
pub fn journal(bytes: &[u8]) {
    let scratch = Scratch::new();
    let dir = &scratch.0;
    let doc = dir.join("doc.json");
    let open = match bytes.starts_with(b"{\"seq\":") {
        true => journal_open_line_v2(),
        false => journal_open_line(),
    };
    let mut text = open.into_bytes();
    text.extend_from_slice(bytes);
    let written = fs::write(&doc, JOURNAL_BASE).and_then(|()| fs::write(journal::path_for(&doc), &text));
    if let Err(e) = written {
        panic!("cannot write the scratch files in {}: {e}", dir.display());
    }
    let strict = Editor::open_read_only(&doc).ok();
    if let Some((editor, report)) = &strict {
        check_document(editor.document(), "the journalled document");
        match Editor::open_read_only(&doc) {
            Ok((again, report_again)) => {
                assert_eq!(again.document(), editor.document(), "the journal replays differently");
                assert_eq!(report_again.replayed, report.replayed);
            }
            Err(e) => panic!("the journal opened once, then not: {e}"),
        }
    }
    let (recovered, report) = match Editor::open_recovering(&doc) {
        Ok(opened) => opened,
        Err(e) => panic!("a journal with a good open line does not open recovering: {e}"),
    };
    match &strict {
        Some((editor, _)) => {
            assert_eq!(
                recovered.document(),
                editor.document(),
                "recovering replays differently"
            );
            assert!(
                report.recovered.is_none(),
                "recovering left out lines of a good journal"
            );
        }
        None => check_document(recovered.document(), "the recovered document"),
    }
}

/// The most cells of a grid the [`grid`] target makes: 65536 (4096 × 16, or 1 × 4096 …).
pub const GRID_CELLS: usize = 1 << 16;

/// The longest side of a grid the [`grid`] target makes.
pub const GRID_SIDE: usize = 4096;

/// A grid from fuzzed bytes: `(cols, rows, cell size, heights)`. Byte 0 and 1 give the long
/// side (1 to [`GRID_SIDE`]), byte 2 the short one (1 to 16), byte 3's low bit whether the long
/// side runs along the columns or the rows, byte 4 the cell size (0.25 to 64 m); the heights are
/// the rest as little-endian `i16` half-metres, repeated to fill the grid (flat without any).
/// Always finite, at most [`GRID_CELLS`] cells.
pub fn grid_of(bytes: &[u8]) -> (u32, u32, f64, Vec<f32>) {
    let at = |i: usize| bytes.get(i).copied().unwrap_or(0);
    let long = (usize::from(u16::from_le_bytes([at(0), at(1)])) % GRID_SIDE) + 1;
    let short = usize::from(at(2) % 16) + 1;
    let (cols, rows) = if at(3) & 1 == 0 { (long, short) } else { (short, long) };
    let cell = 0.25 * f64::from(1 + u32::from(at(4)) % 256);
    let raw = bytes.get(8..).unwrap_or_default();
    let samples: Vec<f32> = raw
        .chunks_exact(2)
        .map(|b| f32::from(i16::from_le_bytes([b[0], b[1]])) * 0.5)
        .collect();
    let z = match samples.is_empty() {
        true => vec![0.0; cols * rows],
        false => samples.iter().copied().cycle().take(cols * rows).collect(),
    };
    (cols as u32, rows as u32, cell, z)
}

/// Any bytes as a small, long or thin grid ([`grid_of`]: 1 × 1 up to 4096 × 16 and 1 × 4096) and
/// a sun and 1 to 8 sky directions from bytes 5 to 7, through the analyses and the sweeps
/// the renderer's land look uses: the rain's moves, pass counts and longest paths, the direct
/// light, the sky view (`ridge::sun::sky_view`, the land look's sky) and the hillshade. Never a
/// panic; every output one value a cell, finite and in its range (moves to a cell of the grid
/// or none; counts and path lengths 1 to the cells; light and sky view in [0, 1]). Issue 47
/// item 3: the sweeps once held every line over every column, the square of the long side —
/// 4096 × 1 asked for 16 M floats — and a run of this target stays fast only while they are
/// bounded by the grid.
pub fn grid(bytes: &[u8]) {
    let (cols, rows, cell, z) = grid_of(bytes);
    let n = z.len();
    let at = |i: usize| bytes.get(i).copied().unwrap_or(0);
    let field = Field {
        z: &z,
        cols,
        rows,
        cell,
    };
    let shape = format!("{cols}×{rows}");
    let next = rain::directions(&z, cols, rows, cell);
    assert_eq!(next.len(), n, "{shape}: directions");
    assert!(
        next.iter().all(|&m| m == rain::STOP || (m as usize) < n),
        "{shape}: a move off the grid"
    );
    for (name, values) in [
        ("pass counts", rain::accumulate(&next)),
        ("longest paths", rain::longest_paths(&next)),
    ] {
        assert_eq!(values.len(), n, "{shape}: {name}");
        assert!(
            values.iter().all(|&v| v >= 1 && v as usize <= n),
            "{shape}: {name} out of 1..={n}"
        );
    }
    let sun = Sun {
        azimuth: f64::from(at(5)) / 256.0 * std::f64::consts::TAU,
        elevation: (1.0 + f64::from(at(6) % 90)).to_radians(),
    };
    let k = u32::from(at(7) % 8) + 1;
    for (name, values) in [
        ("direct light", sun::direct(field, sun)),
        ("sky view", sun::sky_view(field, k)),
        ("hillshade", sun::hillshade(field, sun)),
    ] {
        assert_eq!(values.len(), n, "{shape}: {name}");
        if let Some(i) = values
            .iter()
            .position(|v| !(v.is_finite() && (-1e-4..=1.0 + 1e-4).contains(v)))
        {
            panic!("{shape}: {name} at cell {i} is {}", values[i]);
        }
    }
}

/// The most the heap may grow while [`grid`] runs on a grid of `cells` cells (the `grid` target
/// checks it with a counting allocator): 32 MiB, the sweeps' fixed passes (2²⁰ floats) and
/// rayon's, plus 256 bytes a cell. The sweeps need some 40 bytes a cell; the square of a 4096
/// long side would be 64 MiB of floats.
pub fn grid_heap_bound(cells: usize) -> usize {
    (32 << 20) + 256 * cells
}

/// A directory of this thread's own (tests run in parallel threads), removed when dropped: an
/// execution leaves nothing behind, whichever way it ends.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> Scratch {
        let thread = format!("{:?}", std::thread::current().id());
        let thread: String = thread.chars().filter(char::is_ascii_digit).collect();
        let dir = std::env::temp_dir().join(format!("penscape-fuzz-journal-{}-{thread}", std::process::id()));
        if let Err(e) = fs::create_dir_all(&dir) {
            panic!("cannot create {}: {e}", dir.display());
        }
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}
