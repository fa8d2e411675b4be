//! `penmodel import`: a heightmap in, a document out whose `terrain.base` names it; the sketch
//! drawn on that document is added on top of its heights (`docs/heightmaps.md`).

use std::path::{Component, Path, PathBuf};

use anyhow::{Context, Result, bail};
use penmodel_terrain::document::{Base, BaseHeights, Document, Grid};
use penmodel_terrain::import;

/// Arguments of `penmodel import`.
#[derive(clap::Args)]
#[command(
    after_help = "The kind is told by the name: .png a 16-bit grayscale PNG, .tif/.tiff a float32 GeoTIFF, \
    anything else raw float32 (rows × cols little-endian, row-major, metres; give --size). The document names the \
    heightmap relative to its own folder, so keep the two together.\n\
    Examples:\n  \
    penmodel import dem.tif --out island.json\n  \
    penmodel import volcano.png --out volcano.json                      # a PNG from penmodel generate --png\n  \
    penmodel import scan.png --min 0 --max 812 --cell 5 --out scan.json # a PNG without its range\n  \
    penmodel import dem.f32 --size 512x768 --cell 10 --out dem.json"
)]
pub struct Args {
    /// The heightmap: 16-bit PNG, float32 GeoTIFF or raw float32.
    #[arg(value_name = "HEIGHTMAP")]
    heightmap: PathBuf,
    /// The document to write (JSON).
    #[arg(long, value_name = "DOC.json")]
    out: PathBuf,
    /// A raw float32 file's size, rows × cols.
    #[arg(long, value_name = "ROWSxCOLS", value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// The side of a cell on the ground, metres: needed where the file does not record it
    /// (raw float32; a PNG without a cell_size_m chunk; a TIFF without ModelPixelScale), and
    /// used instead of the file's when given.
    #[arg(long, value_name = "M")]
    cell: Option<f64>,
    /// The height of a 16-bit PNG's value 0, metres (with --max), for a PNG that does not record its range.
    #[arg(long, value_name = "M", requires = "max", allow_hyphen_values = true)]
    min: Option<f64>,
    /// The height of a 16-bit PNG's value 65535, metres (with --min).
    #[arg(long, value_name = "M", requires = "min", allow_hyphen_values = true)]
    max: Option<f64>,
}

/// Parses `--size ROWSxCOLS`.
fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (r, c) = text
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("expected ROWSxCOLS (e.g. 512x768), got `{text}`"))?;
    let n = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("`{s}` is not a count of cells above 0"))
    };
    Ok((n(r)?, n(c)?))
}

/// A path's parts without `.`.
fn clean(p: &Path) -> Vec<Component<'_>> {
    p.components().filter(|c| *c != Component::CurDir).collect()
}

/// `target` relative to the folder `from`, both made canonical (links and `..` resolved); `None`
/// if either is not there or they share no root.
fn relative(target: &Path, from: &Path) -> Option<PathBuf> {
    let target = std::fs::canonicalize(target).ok()?;
    let from = std::fs::canonicalize(from).ok()?;
    let (t, f) = (clean(&target), clean(&from));
    if t.first() != f.first() || t.iter().chain(&f).any(|c| *c == Component::ParentDir) {
        return None;
    }
    let common = t.iter().zip(&f).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    Some(out)
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let kind = import::Kind::of(&args.heightmap);
    if (args.min.is_some() || args.size.is_some()) && kind == import::Kind::GeoTiff {
        bail!("--min/--max and --size are for a PNG and a raw file; a GeoTIFF records its size and heights");
    }
    if args.size.is_some() && kind == import::Kind::Png16 {
        bail!("--size is for a raw float32 file; a PNG records its size");
    }
    if let Some(cell) = args.cell
        && !(cell.is_finite() && cell > 0.0)
    {
        bail!("--cell must be a number of metres above 0, got {cell}");
    }
    let range = args.min.zip(args.max);
    if let Some((min, max)) = range
        && !(min.is_finite() && max.is_finite() && min <= max)
    {
        bail!("--min and --max must be finite with --min ≤ --max, got {min} and {max}");
    }
    let read = import::read(&args.heightmap, &import::Options { size: args.size, range })?;
    let Some(cell_size) = args.cell.or(read.cell_size) else {
        bail!(
            "{} does not record its cell size: give --cell M (metres per cell)",
            args.heightmap.display()
        );
    };
    let dir = args.out.parent().unwrap_or(Path::new(""));
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let named = relative(&args.heightmap, dir)
        .or_else(|| std::fs::canonicalize(&args.heightmap).ok())
        .unwrap_or_else(|| args.heightmap.clone());
    let Some(named) = named.to_str() else {
        bail!("the heightmap's path {} is not UTF-8 text", named.display());
    };
    let mut doc = Document::new(Grid {
        cols: read.cols,
        rows: read.rows,
        cell_size,
    });
    let mut base = Base::new(named.replace('\\', "/"));
    // A PNG's range given on the command line goes into the document (the file does not hold it).
    if read.kind == import::Kind::Png16 {
        base.min = args.min;
        base.max = args.max;
    }
    let (lo, hi) = read
        .heights
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| {
            (lo.min(h), hi.max(h))
        });
    base.heights = BaseHeights::new(read.heights);
    doc.terrain.base = Some(base);
    doc.note = Some(format!("imported from {}", args.heightmap.display()));
    doc.save(&args.out)
        .with_context(|| format!("cannot make a document of {}", args.heightmap.display()))?;
    pen_host::outln!(
        "imported {} ({}): {} × {} cells of {cell_size} m, heights {}; saved {} (terrain.base: {named})",
        args.heightmap.display(),
        read.kind,
        read.cols,
        read.rows,
        crate::out::metres_range(lo, hi),
        args.out.display()
    );
    Ok(())
}
