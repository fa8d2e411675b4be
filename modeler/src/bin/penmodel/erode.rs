//! `penmodel erode`: a document's fluvial erosion alone (`docs/erosion.md`), step by step with
//! progress: the land before and after as heightmaps, and the drainage signatures of both.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::fluvial::{self, measure};
use penmodel_terrain::{Fluvial, Heightmap, export};

/// Arguments of `penmodel erode`.
#[derive(clap::Args)]
#[command(
    after_help = "The document's own fluvial settings (terrain.erosion.fluvial) are used, or the defaults when it has none.\n\
    Examples (from the repository's folder):\n  \
    penmodel erode modeler/examples/04-volcano.json --png volcano-eroded.png\n  \
    penmodel erode modeler/examples/01-ridges-and-peaks.json --steps 200 --json"
)]
pub struct Args {
    /// The document (JSON). A pending journal beside it is replayed, read-only.
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// Steps instead of the settings' (1 to 5000).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=i64::from(penmodel_terrain::validate::MAX_FLUVIAL_STEPS)))]
    steps: Option<u32>,
    /// The eroded land as raw float32 (rows × cols, little-endian, row-major, metres).
    #[arg(long, value_name = "OUT.f32")]
    raw: Option<PathBuf>,
    /// The eroded land as a 16-bit grayscale PNG (its height range in tEXt chunks).
    #[arg(long, value_name = "OUT.png")]
    png: Option<PathBuf>,
    /// Print the settings, the time per step and the signatures before and after as JSON.
    #[arg(long)]
    json: bool,
}

fn write(map: &Heightmap, path: &Path, png: bool) -> Result<()> {
    let mut bytes = Vec::new();
    if png {
        export::write_png(map, &mut bytes).map(|_| ())
    } else {
        export::write_raw(map, &mut bytes)
    }
    .with_context(|| format!("cannot export {}", path.display()))?;
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let (editor, _) = Editor::open_read_only(&args.doc)?;
    let doc = editor.document();
    let mut settings: Fluvial = doc.terrain.erosion.and_then(|e| e.fluvial).unwrap_or_default();
    if let Some(n) = args.steps {
        settings.steps = n;
    }
    let sketch = editor.terrain().sketch();
    let bar = ProgressBar::with_draw_target(Some(u64::from(settings.steps)), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("eroding {bar:30} {pos}/{len} steps, {per_sec}, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let t = Instant::now();
    let mut model = fluvial::Model::new(settings, sketch).holding(fluvial::held_cells(doc));
    while !model.finished() {
        model.advance(1);
        bar.inc(1);
    }
    let elapsed = t.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let mut land = sketch.clone();
    model.write(&mut land);
    let before = measure::signatures(sketch, None);
    let after = measure::signatures(&land, None);
    if let Some(p) = &args.raw {
        write(&land, p, false)?;
    }
    if let Some(p) = &args.png {
        write(&land, p, true)?;
    }
    let ms_per_step = elapsed * 1e3 / f64::from(settings.steps.max(1));
    if args.json {
        let out = serde_json::json!({
            "grid": [land.cols(), land.rows()],
            "settings": settings,
            "steps": settings.steps,
            "ms_per_step": ms_per_step,
            "before": before,
            "after": after,
        });
        pen_host::outln!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        let (lo, hi) = land.range();
        pen_host::outln!(
            "eroded {}×{} cells by {} steps ({:.1} ms a step); land {}",
            land.cols(),
            land.rows(),
            settings.steps,
            ms_per_step,
            crate::out::metres_range(lo, hi)
        );
        for (name, s) in [("before", before), ("after", after)] {
            pen_host::outln!(
                "{name:>6}: area τ {:.2}, Hack's h {:.2}, slope mode share {:.2}, {} pits (deepest {:.1} m)",
                s.area_tau,
                s.hack_h,
                s.slope_mode_share,
                s.pits,
                s.pit_depth_max
            );
        }
        for p in [&args.raw, &args.png].into_iter().flatten() {
            pen_host::outln!("wrote {}", p.display());
        }
    }
    Ok(())
}
