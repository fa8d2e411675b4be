//! The session's results: the final terrain (16-bit PNG, float32, meshes on request), its
//! renders as the display and the overview show it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use penmodel::interaction::View;
use penmodel::painter::Painter;
use penmodel::picture::{Look, Picture};
use penmodel::session::Session;
use penmodel_render::output;
use penmodel_terrain::{Heightmap, export};
use serde_json::json;

/// Writes the final terrain, its render and the exports; returns what was written, by kind.
pub fn write(
    out: &Path,
    meshes: bool,
    session: &Session,
    look: &Look,
    painter: &mut Painter,
) -> Result<serde_json::Value> {
    let map: &Heightmap = session.editor.heightmap();
    let write = |name: &str, bytes: &[u8]| -> Result<PathBuf> {
        let path = out.join(name);
        penmodel_terrain::persist::write_atomic(&path, bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(path)
    };
    let mut bytes = Vec::new();
    export::write_png(map, &mut bytes)?;
    let png = write("terrain.png", &bytes)?;
    bytes.clear();
    export::write_raw(map, &mut bytes)?;
    let raw = write("terrain.f32", &bytes)?;
    // Meshes are large (a 512² grid is 18 MB of OBJ) and derived from the heightmap: on request.
    let (mut obj, mut glb) = (None, None);
    if meshes {
        bytes.clear();
        export::write_obj_with(map, session.editor.rocks().meshes(), &mut bytes)?;
        obj = Some(write("terrain.obj", &bytes)?);
        bytes.clear();
        export::write_glb_with(map, session.editor.rocks().meshes(), &mut bytes)?;
        glb = Some(write("terrain.glb", &bytes)?);
    }
    // The final state, without the pen or a highlight, the ground level: as the display shows
    // it, and from the orbit camera of the overview.
    let view = View {
        tilt: 0.0,
        ..*session.interaction.view()
    };
    let (lo, hi) = map.range();
    let mode = format!("penmodel: final terrain, {}", crate::out::metres_range(lo, hi));
    // The trees at the last event's time, as the last frame drew them.
    let picture = Picture::document(session.editor.document(), &view, mode, look)
        .with_rocks(session.editor.rocks().shared())
        .with_trees(session.editor.trees().shared())
        .with_time(session.last_event_us().map_or(0.0, |us| us as f64 * 1e-6));
    bytes.clear();
    output::encode_png(painter.plain(&picture, map)?, &mut bytes)?;
    let display = write("display.png", &bytes)?;
    let extent = [
        f64::from(map.cols()) * map.cell_size(),
        f64::from(map.rows()) * map.cell_size(),
    ];
    bytes.clear();
    output::encode_png(painter.plain(&picture.overview(extent), map)?, &mut bytes)?;
    let render = write("render.png", &bytes)?;
    Ok(json!({
        "heightmap_png": png, "heightmap_f32": raw, "mesh_obj": obj, "mesh_glb": glb,
        "render": render, "display": display,
    }))
}
