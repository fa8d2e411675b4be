//! `penmodel generate`: document in, heightmap and meshes out.

use std::path::PathBuf;

use anyhow::{Context, Result};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::export::{GlbScene, Material, Mesh, Part};
use penmodel_terrain::rocks::cache::Rocks;
use penmodel_terrain::trees::nodes::STOP;
use penmodel_terrain::trees::planted::Shared;
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
    /// The terrain mesh as binary glTF: materials (the land look's ground colours per vertex,
    /// water, rock, bark, leaves) and each species' tree once, drawn at every tree's place
    /// (EXT_mesh_gpu_instancing, required).
    #[arg(long, value_name = "OUT.glb")]
    glb: Option<PathBuf>,
    /// Leave the trees and groves out of the meshes (--obj, --glb).
    #[arg(long)]
    no_trees: bool,
    /// Leave the rock fields out of the meshes.
    #[arg(long)]
    no_rocks: bool,
    /// Leave the rivers' and lakes' water out of the meshes.
    #[arg(long)]
    no_water: bool,
    /// The trees' roughness Q in [0.02, 1] in the meshes: branch groups no larger than Q·height
    /// become crossed cards (untextured, leaf-coloured); 0.02 (the default) is the full tree.
    #[arg(long, value_name = "Q", default_value_t = STOP, value_parser = parse_detail, conflicts_with = "no_trees")]
    tree_detail: f64,
}

/// Parses `--tree-detail Q`: a roughness in [STOP, 1].
fn parse_detail(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(q) if (STOP..=1.0).contains(&q) => Ok(q),
        _ => Err(format!(
            "expected a roughness from {STOP} (the full tree) to 1 (cards only), got `{text}`"
        )),
    }
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
    let meshes = args.obj.is_some() || args.glb.is_some();
    // The document's rock fields stand on the terrain in the meshes (an object or node each;
    // each rock is seated on the ground, so no two are alike and none is instanced).
    let rocks = if meshes && !args.no_rocks {
        Rocks::of(editor.document()).seated(map)
    } else {
        Vec::new()
    };
    // The rivers' and lakes' water surface: a separate mesh (object or node) "water".
    let water = editor
        .water()
        .filter(|w| w.any() && meshes && !args.no_water)
        .map(|w| w.mesh(map.cell_size()));
    let trees = !editor.trees().trees().is_empty() && meshes && !args.no_trees;
    if args.obj.is_some() {
        let mut placed = rocks.clone();
        placed.extend(water.iter().map(|w| ("water".to_string(), w.clone())));
        // The trees and groves standing on the terrain at rest: one mesh "trees".
        if trees {
            let drawn = editor.trees().draw(|_| args.tree_detail, 0.0);
            placed.push(("trees".to_string(), drawn.mesh));
        }
        export(map, &args.obj, |m, out| export::write_obj_with(m, &placed, out))?;
    }
    if args.glb.is_some() {
        let shared = if trees {
            editor.trees().instanced(args.tree_detail)
        } else {
            Vec::new()
        };
        export(map, &args.glb, |m, out| {
            write_scene(m, &rocks, water.as_ref(), &shared, out)
        })?;
    }
    let (lo, hi) = map.range();
    let journal = if report.replayed > 0 {
        format!(", {} journal entries replayed", report.replayed)
    } else {
        String::new()
    };
    pen_host::outln!("{} × {} cells, heights {lo} to {hi} m{journal}", map.cols(), map.rows());
    Ok(())
}

/// sRGB (0–255) to linear (0–1), as glTF's colours are.
fn linear(c: [f32; 3]) -> [f32; 3] {
    c.map(|v| {
        let v = (v / 255.0).clamp(0.0, 1.0);
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// The GLB of `generate`: the terrain with the land look's ground colours as COLOR_0, the rock
/// fields, the water, and each species' tree once with its trees as instances.
fn write_scene(
    map: &Heightmap,
    rocks: &[(String, Mesh)],
    water: Option<&Mesh>,
    trees: &[Shared],
    out: &mut Vec<u8>,
) -> Result<(), export::ExportError> {
    use penmodel_render::land;
    use penmodel_terrain::trees::shapes::{BARK, LEAF};
    let mut terrain = Mesh::of(map)?;
    terrain.colors = land::ground_colours(map, &penmodel_render::Style::land())
        .into_iter()
        .map(linear)
        .collect();
    let (ground, water_m, rock, bark, leaves) = (0, 1, 2, 3, 4);
    let materials = vec![
        Material::vertex_coloured("ground"),
        Material::water(),
        Material::opaque("rock", linear(land::ROCK.map(f32::from)), 0.95),
        Material::opaque("bark", BARK, 0.9),
        // Untextured leaves: plain green, opaque, seen from both sides.
        Material {
            double_sided: true,
            ..Material::opaque("leaves", LEAF, 0.8)
        },
    ];
    let mut parts = vec![Part {
        name: "terrain".to_string(),
        primitives: vec![(&terrain, ground)],
        instances: None,
    }];
    parts.extend(rocks.iter().map(|(name, mesh)| Part {
        name: name.clone(),
        primitives: vec![(mesh, rock)],
        instances: None,
    }));
    parts.extend(water.map(|mesh| Part {
        name: "water".to_string(),
        primitives: vec![(mesh, water_m)],
        instances: None,
    }));
    parts.extend(trees.iter().map(|t| Part {
        name: t.name.clone(),
        primitives: vec![(&t.bark, bark), (&t.leaves, leaves)],
        instances: Some(t.instances.clone()),
    }));
    export::write_glb_scene(&GlbScene { materials, parts }, out)
}
