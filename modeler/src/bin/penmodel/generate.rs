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
    group(clap::ArgGroup::new("outputs").args(["raw", "png", "obj", "glb"]).required(true).multiple(true)),
    after_help = "Give at least one output: --raw, --png, --obj or --glb.\n\
    Examples (from the repository's folder):\n  \
    penmodel generate modeler/examples/04-volcano.json --png volcano.png\n  \
    penmodel generate modeler/examples/04-volcano.json --raw volcano.f32 --glb volcano.glb"
)]
pub struct Args {
    /// The document (JSON). A pending journal beside it (DOC.json.journal) is replayed, read-only.
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// Heights as raw float32: rows × cols little-endian, row-major (index r·cols + c), metres.
    #[arg(long, value_name = "OUT.f32")]
    raw: Option<PathBuf>,
    /// Heights as a 16-bit grayscale PNG; the height range is in its tEXt chunks.
    #[arg(long, value_name = "OUT.png")]
    png: Option<PathBuf>,
    /// The terrain mesh as Wavefront OBJ.
    #[arg(long, value_name = "OUT.obj")]
    obj: Option<PathBuf>,
    /// The terrain mesh as binary glTF.
    #[arg(long, value_name = "OUT.glb")]
    glb: Option<PathBuf>,
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
    export(map, &args.png, |m, out| export::write_png(m, out).map(|_| ()))?;
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
