//! `penmodel trees scene`: the seed's forest scene (§3.5.2: 30 trees at varied turns, sizes and
//! distances, 270 000 → 16 000 polygons) rendered with level of detail off and on.
//!
//! - Terrain: example 1 (`examples/01-ridges-and-peaks.json`, 160² cells of 2 m), the land look
//!   (`--look classic`: the first renderer's).
//! - Camera: an orbit at eye height over the grid's middle (azimuth 30°, elevation 10°, 40 m
//!   away, 45° field of view), so the trees stand from near to far as in the seed's picture.
//! - Trees: the seed's two species of Table 3.1 in turn (even k Sample 3.1, `table-3.1`; odd k
//!   Sample 3.2, `sample-3.2`: 15 of each in 30, as the seed's scene), 8–14 m tall, turned by
//!   their index; tree k stands at a distance growing geometrically from 18 m to 150 m from the
//!   eye along the ground, at an angle across the view from a golden-ratio sequence within ±28°
//!   (inside the 16:9 frame's ±36° horizontally).
//! - LOD off: every tree in full (`Scene::tree_lod` `None`); on: the default `Roughness` by
//!   distance and gaze (the view axis). Stereo: the anaglyph, two full-size eyes with the trees
//!   drawn once for both.
//! - Times: medians of `--frames` frames after one untimed frame (which bakes the simplified
//!   shapes' textures and the land look's light); the scene does not change between frames.
//! - Image difference between the LOD-off and LOD-on mono frames: mean absolute difference per
//!   RGB channel (0–255) and PSNR (dB), [`Frame::difference`].

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::DVec3;
use penmodel_render::{Camera, Eye, Frame, Orbit, Renderer, Scene, Stereo, Style, View};
use penmodel_terrain::trees::planted::turn;
use penmodel_terrain::trees::{NodeTree, Preset, Source, Species, Standing};
use penmodel_terrain::{Document, Editor};
use serde_json::json;

/// Most trees in the scene (the layout's distances stay inside example 1's grid).
const MAX_TREES: u32 = 200;

#[derive(clap::Args)]
pub struct SceneArgs {
    /// How many trees (the seed's scene: 30).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=MAX_TREES as i64))]
    trees: u32,
    /// Time frames: LOD off and on mono, LOD on in stereo (otherwise one frame each, untimed).
    #[arg(long)]
    bench: bool,
    /// With --bench, draw the full-detail frame once, untimed (for the image difference): a
    /// profile of the LOD frames.
    #[arg(long)]
    lod_only: bool,
    /// Timed frames per case with --bench (the median is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    frames: u32,
    /// With --bench, turn the view by this many degrees about its target from one timed frame
    /// to the next (0: a still view). A moving view redraws what a still one keeps: the
    /// background behind the surfaces, and the trees' levels of detail change.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, allow_hyphen_values = true, value_parser = turn_degrees)]
    turn: f64,
    /// Frame width, pixels.
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(16..=8192))]
    width: u32,
    /// Frame height, pixels.
    #[arg(long, default_value_t = 720, value_parser = clap::value_parser!(u32).range(16..=8192))]
    height: u32,
    /// The figures as JSON (docs/trees.md); `-` or no value for stdout.
    #[arg(long, value_name = "FILE", num_args = 0..=1, default_missing_value = "-")]
    json: Option<PathBuf>,
    /// The look: the land look (what `penmodel render` and the demo show) or the classic one.
    #[arg(long, value_enum, default_value = "land")]
    look: crate::render::LookArg,
    /// Write the mono frames as DIR/full.png and DIR/lod.png (and with --bench the LOD stereo
    /// frame as DIR/stereo.png).
    #[arg(long, value_name = "DIR")]
    png: Option<PathBuf>,
}

/// The scene's trees on `map` (`extent` metres across), seen from `camera` in a frame of `aspect`.
fn layout(n: u32, map: &penmodel_terrain::Heightmap, extent: [f64; 2], camera: &Camera, aspect: f64) -> Vec<Standing> {
    let species = [Preset::Table31, Preset::Sample32].map(|p| Arc::new(NodeTree::build(&Species::preset(p))));
    let vp = camera.viewpoint(Eye::Centre, aspect);
    let centre = 0.5 * (vp.lower_right + vp.upper_left);
    let ahead = DVec3::new(centre.x - vp.eye.x, 0.0, centre.z - vp.eye.z).normalize_or(DVec3::X);
    let across = DVec3::new(-ahead.z, 0.0, ahead.x);
    let ground = penmodel_terrain::rocks::place::ground(map);
    let [w, h] = extent;
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    (0..n)
        .map(|k| {
            let f = if n > 1 { f64::from(k) / f64::from(n - 1) } else { 0.0 };
            let distance = 25.0 * (200.0f64 / 25.0).powf(f);
            let angle = (2.0 * (f64::from(k) * golden).fract() - 1.0) * 28f64.to_radians();
            let p = vp.eye + distance * (angle.cos() * ahead + angle.sin() * across);
            let at = [p.x.clamp(1.0, w - 1.0), p.z.clamp(1.0, h - 1.0)];
            Standing {
                source: Source::Tree(k as usize),
                at,
                base: ground.height(at[0], at[1]),
                height: 8.0 + 6.0 * (f64::from(k) * golden * golden).fract(),
                turn: turn(u64::from(k)),
                nodes: Arc::clone(&species[k as usize % 2]),
                wind: None,
            }
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// `--turn`'s degrees: finite, at most 10 a frame.
fn turn_degrees(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v.abs() <= 10.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a turn from -10 to 10 degrees a frame"))
    }
}

/// Renders `scene` once untimed, then `frames` times, the view turned by `turn` degrees about
/// its orbit's target each timed frame; the median in ms (`None` when untimed). `frame` ends
/// with the still view (drawn once more, untimed, after turning), so that the pictures and the
/// image difference are the same whatever the turn.
fn time(
    renderer: &mut Renderer,
    scene: &Scene,
    frame: &mut Frame,
    frames: Option<u32>,
    turn: f64,
) -> Result<Option<f64>> {
    renderer.render(scene, frame)?;
    let Some(n) = frames else { return Ok(None) };
    let mut ms = Vec::with_capacity(n as usize);
    let mut turned = scene.clone();
    for i in 1..=n {
        if let View::Orbit(o) = &mut turned.camera.view
            && let View::Orbit(start) = &scene.camera.view
        {
            o.azimuth = start.azimuth + (f64::from(i) * turn).to_radians();
        }
        let t = Instant::now();
        renderer.render(&turned, frame)?;
        ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    if turn != 0.0 {
        renderer.render(scene, frame)?;
    }
    Ok(Some(median(ms)))
}

fn round3(v: f64) -> f64 {
    (v * 1e3).round() / 1e3
}

/// Runs `penmodel trees scene`.
pub fn run(args: &SceneArgs) -> Result<()> {
    let doc = Document::from_json(include_str!("../../../../examples/01-ridges-and-peaks.json"))
        .context("example 1 is not valid")?;
    let centre = [0.5 * doc.grid.width(), 0.5 * doc.grid.height()];
    let editor = Editor::new(doc)?;
    let map = editor.heightmap();
    let ground = penmodel_terrain::rocks::place::ground(map);
    let mut orbit = Orbit::overview(
        [2.0 * centre[0], 2.0 * centre[1]],
        30f64.to_radians(),
        18f64.to_radians(),
    );
    orbit.distance = 60.0;
    orbit.target_height = ground.height(centre[0], centre[1]) + 3.0;
    let camera = Camera {
        view: View::Orbit(orbit),
        tilt: 0.0,
    };
    let aspect = f64::from(args.width) / f64::from(args.height);
    let trees = layout(args.trees, map, [2.0 * centre[0], 2.0 * centre[1]], &camera, aspect);
    let mut scene = Scene::new(map, camera);
    // As the live loop: the renderer learns from the editor what changed since its last frame
    // (nothing, in this still scene), where without it every frame rebuilt the terrain's
    // level-of-detail pyramid and compared the heights with a copy.
    scene.revisions = Some(editor.revisions());
    scene.trees = &trees;
    match args.look {
        crate::render::LookArg::Land => {
            scene.style = Style::land();
            // A still scene: the light on the heightmap's own grid, made once.
            scene.style.light_cells = 0;
            scene.style.sky_directions = 32;
        }
        crate::render::LookArg::Classic => scene.style.ramp_top = crate::render::ramp_top(map.range().1),
    }
    let look = match args.look {
        crate::render::LookArg::Land => "land",
        crate::render::LookArg::Classic => "classic",
    };
    let lod = scene.tree_lod;
    let frames = args.bench.then_some(args.frames);
    let mut renderer = Renderer::new();
    let mut full = Frame::new(args.width, args.height)?;
    let mut on = Frame::new(args.width, args.height)?;

    scene.tree_lod = None;
    let ms_full = time(
        &mut renderer,
        &scene,
        &mut full,
        frames.filter(|_| !args.lod_only),
        args.turn,
    )?;
    let stats_full = renderer.tree_stats();
    scene.tree_lod = lod;
    let ms_lod = time(&mut renderer, &scene, &mut on, frames, args.turn)?;
    let stats_lod = renderer.tree_stats();
    let (ms_stereo, pair) = if args.bench {
        scene.stereo = Stereo::Anaglyph;
        let mut pair = Frame::new(args.width, args.height)?;
        let ms = time(&mut renderer, &scene, &mut pair, frames, args.turn)?;
        scene.stereo = Stereo::None;
        (ms, Some(pair))
    } else {
        (None, None)
    };
    let Some((mad, psnr)) = full.difference(&on) else {
        bail!("the two frames differ in size");
    };
    if let Some(dir) = &args.png {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let frames = [
            ("full.png", Some(&full)),
            ("lod.png", Some(&on)),
            ("stereo.png", pair.as_ref()),
        ];
        for (name, f) in frames.into_iter().filter_map(|(n, f)| Some((n, f?))) {
            let path = dir.join(name);
            penmodel_render::output::write_png(f, &path).with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    let metric =
        "mean absolute difference per RGB channel (0-255) and PSNR (dB) between the LOD-off and LOD-on mono frames";
    if let Some(path) = &args.json {
        let v = json!({
            "trees": stats_full.trees, "width": args.width, "height": args.height,
            "frames": frames, "stereo": "anaglyph", "look": look, "turn_deg_per_frame": args.turn,
            "frame_ms_full": ms_full.map(round3), "frame_ms_lod": ms_lod.map(round3),
            "frame_ms_lod_stereo": ms_stereo.map(round3),
            "polygons_full": stats_full.total_polygons(), "polygons_lod": stats_lod.total_polygons(),
            "lod_copied": stats_lod.polygons, "lod_shapes": stats_lod.impostors,
            "image_difference": {"mean_abs": round3(mad), "psnr_db": round3(psnr)},
            "image_metric": metric,
        });
        let mut text = serde_json::to_string(&v)?;
        text.push('\n');
        super::write(path, text.as_bytes())?;
    }
    let json = args.json.as_deref();
    let show = |ms: Option<f64>| ms.map_or("untimed".to_owned(), |m| format!("{m:.1} ms"));
    super::say(
        json,
        &format!(
            "{} Table 3.1 trees (Samples 3.1 and 3.2 in turn) on example 1 at {}×{}, {look} look: full {} polygons, {}; LOD {} polygons ({} copied + {} shapes), {}; LOD stereo (anaglyph) {}",
            stats_full.trees,
            args.width,
            args.height,
            stats_full.total_polygons(),
            show(ms_full),
            stats_lod.total_polygons(),
            stats_lod.polygons,
            stats_lod.impostors,
            show(ms_lod),
            show(ms_stereo),
        ),
    )?;
    super::say(
        json,
        &format!("image difference full vs LOD: mean abs {mad:.3}/255 per channel, PSNR {psnr:.1} dB"),
    )?;
    if args.bench {
        super::say(
            json,
            &format!(
                "medians of {} frames{}; targets with LOD: ≤ 16.7 ms mono, ≤ 33 ms stereo",
                args.frames,
                if args.turn == 0.0 {
                    " of a still view".to_owned()
                } else {
                    format!(" of a view turning {}° a frame", args.turn)
                }
            ),
        )?;
    }
    Ok(())
}
