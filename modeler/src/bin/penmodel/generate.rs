//! `penmodel generate`: document in, heightmap and meshes out.

use std::path::PathBuf;

use anyhow::{Context, Result};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::rocks::cache::Rocks;
use penmodel_terrain::{Heightmap, export, journal, persist};

use crate::out::write;

/// Arguments of `penmodel generate`: at least one output.
#[derive(clap::Args)]
#[command(
    group(clap::ArgGroup::new("outputs").args(["raw", "png", "raw16", "geotiff", "obj", "glb"]).required(true).multiple(true)),
    after_help = "Give at least one output: --raw, --png, --raw16, --geotiff, --obj or --glb. \
    --png, --raw16 and --geotiff each get a sidecar FILE.json (size, cell size, height range, scale): docs/heightmaps.md.\n\
    Examples (from the repository's folder):\n  \
    penmodel generate modeler/examples/04-volcano.json --png volcano.png\n  \
    penmodel generate modeler/examples/04-volcano.json --raw16 volcano.r16 --geotiff volcano.tif --origin 500000,4100000\n  \
    penmodel generate modeler/examples/04-volcano.json --raw volcano.f32 --glb volcano.glb"
)]
pub struct Args {
    /// The document (JSON). A pending journal beside it (DOC.json.journal) is replayed, read-only.
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// Heights as raw float32: rows × cols little-endian, row-major (index r·cols + c), metres.
    #[arg(long, value_name = "OUT.f32")]
    raw: Option<PathBuf>,
    /// Heights as a 16-bit grayscale PNG (Unreal); the height range is in its tEXt chunks and the sidecar OUT.png.json.
    #[arg(long, value_name = "OUT.png")]
    png: Option<PathBuf>,
    /// Heights as RAW16 (Unity): rows × cols little-endian u16, row-major, 0..65535 over the height range; sidecar OUT.r16.json.
    #[arg(long, value_name = "OUT.r16")]
    raw16: Option<PathBuf>,
    /// Heights as a float32 GeoTIFF with a geotransform from the cell size and --origin (QGIS, GDAL); sidecar OUT.tif.json.
    #[arg(long, value_name = "OUT.tif")]
    geotiff: Option<PathBuf>,
    /// The GeoTIFF's upper-left corner, metres in its CRS (rows run south from it).
    #[arg(long, value_name = "X,Y", default_value = "0,0", value_parser = parse_origin, allow_hyphen_values = true, requires = "geotiff")]
    origin: [f64; 2],
    /// The GeoTIFF's projected CRS as an EPSG code (e.g. 32654 for UTM 54N); left out: local, unknown.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1024..=32767), requires = "geotiff")]
    epsg: Option<u32>,
    /// The terrain mesh as Wavefront OBJ.
    #[arg(long, value_name = "OUT.obj")]
    obj: Option<PathBuf>,
    /// The terrain mesh as binary glTF.
    #[arg(long, value_name = "OUT.glb")]
    glb: Option<PathBuf>,
}

/// Parses `--origin X,Y`: two finite numbers, metres.
fn parse_origin(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [x, y] = parts[..] else {
        return Err(format!("expected X,Y in metres (e.g. 500000,4100000), got `{text}`"));
    };
    let num = |s: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{s}` is not a finite number of metres"))
    };
    Ok([num(x)?, num(y)?])
}

/// Exports a heightmap with `f` (which returns the height range it wrote) and its sidecar beside it
/// (none for standard output).
fn export_with_sidecar(
    map: &Heightmap,
    path: &Option<PathBuf>,
    format: export::Format,
    geo: Option<export::GeoRef>,
    f: impl FnOnce(&Heightmap, &mut Vec<u8>) -> Result<export::HeightRange, export::ExportError>,
) -> Result<()> {
    let Some(path) = path else { return Ok(()) };
    let mut bytes = Vec::new();
    let range = f(map, &mut bytes).with_context(|| format!("cannot export {}", path.display()))?;
    write(path, &bytes)?;
    if path != std::path::Path::new("-") {
        let mut sidecar = export::Sidecar::new(format, map, range);
        if let Some(geo) = geo {
            sidecar.origin_m = Some(geo.origin);
            sidecar.epsg = geo.epsg;
        }
        write(&export::sidecar_path(path), sidecar.to_json().as_bytes())?;
    }
    Ok(())
}

fn export(
    map: &Heightmap,
    path: &Option<PathBuf>,
    f: impl FnOnce(&Heightmap, &mut Vec<u8>) -> Result<(), export::ExportError>,
) -> Result<()> {
    if let Some(path) = path {
        let mut bytes = Vec::new();
        f(map, &mut bytes).with_context(|| format!("cannot export {}", path.display()))?;
        write(path, &bytes)?;
    }
    Ok(())
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let (editor, report) = Editor::open_read_only(&args.doc)?;
    // The terrain is the saved document's alone then; say so rather than silently leave out
    // edits the user may expect.
    if let Some(stale) = &report.ignored_stale_journal {
        eprintln!(
            "penmodel: {} was not replayed: it was written for another version of {} (it is left as it is; \
             `penmodel open` sets it aside)",
            stale.display(),
            args.doc.display()
        );
    }
    if report.dropped_torn_line {
        eprintln!(
            "penmodel: the last line of {} was cut off by a crash and was not replayed",
            journal::path_for(&persist::resolve_link(&args.doc).unwrap_or_else(|_| args.doc.clone())).display()
        );
    }
    let map = editor.heightmap();
    export(map, &args.raw, |m, out| export::write_raw(m, out))?;
    export_with_sidecar(map, &args.png, export::Format::Png16, None, |m, out| {
        export::write_png(m, out)
    })?;
    export_with_sidecar(map, &args.raw16, export::Format::Raw16, None, |m, out| {
        export::write_raw16(m, out)
    })?;
    let geo = export::GeoRef {
        origin: args.origin,
        epsg: args.epsg,
    };
    export_with_sidecar(map, &args.geotiff, export::Format::Geotiff, Some(geo), |m, out| {
        export::write_geotiff(m, geo, out)
    })?;
    // The document's rock fields stand on the terrain in the meshes (an object or node each),
    // and the rivers' water is one more.
    let mut placed = if args.obj.is_some() || args.glb.is_some() {
        Rocks::of(editor.document()).seated(map)
    } else {
        Vec::new()
    };
    // The rivers' and lakes' water surface: a separate mesh (object or node) "water".
    if let Some(water) = editor.water().filter(|w| w.any())
        && (args.obj.is_some() || args.glb.is_some())
    {
        placed.push(("water".to_string(), water.mesh(map.cell_size())));
    }
    // The trees and groves standing on the terrain, full geometry at rest: one mesh "trees".
    if !editor.trees().trees().is_empty() && (args.obj.is_some() || args.glb.is_some()) {
        let drawn = editor.trees().draw(|_| penmodel_terrain::trees::nodes::STOP, 0.0);
        placed.push(("trees".to_string(), drawn.mesh));
    }
    export(map, &args.obj, |m, out| export::write_obj_with(m, &placed, out))?;
    export(map, &args.glb, |m, out| export::write_glb_with(m, &placed, out))?;
    let (lo, hi) = map.range();
    let journal = if report.replayed > 0 {
        format!(", {} journal entries replayed", report.replayed)
    } else {
        String::new()
    };
    pen_host::outln!("{} × {} cells, heights {lo} to {hi} m{journal}", map.cols(), map.rows());
    Ok(())
}
