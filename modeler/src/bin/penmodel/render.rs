//! `penmodel render`: a document's terrain drawn by the CPU rasteriser into a PNG.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::ValueEnum;
use penmodel_render::output;
use penmodel_render::{self as render, Camera, Frame, Orbit, Renderer, Scene, Stereo, Tracked, View};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::ridge::sun::{self, Field, Sun as SunPosition};

/// Stereo modes on the command line.
#[derive(Clone, Copy, ValueEnum)]
pub enum StereoArg {
    /// One image.
    None,
    /// Red–cyan anaglyph.
    Anaglyph,
    /// Left eye in the left half, right eye in the right half.
    SideBySide,
}

/// Looks on the command line.
#[derive(Clone, Copy, ValueEnum)]
pub enum LookArg {
    /// Colour by height in metres and slope, shadows and sky light, sky, table and haze.
    Land,
    /// The first renderer's look: one elevation ramp whose top tenth is snow, Lambert light.
    Classic,
}

/// `W×H` or `WxH`, positive integers.
pub fn size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("{v:?}: {e}"));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 || w > render::MAX_SIDE || h > render::MAX_SIDE {
        return Err(format!("each side must be 1 to {}", render::MAX_SIDE));
    }
    Ok((w, h))
}

/// `W×H` in metres (the earlier `--display`).
fn display(s: &str) -> Result<[f64; 2], String> {
    let (w, h) = s
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT in metres, got {s:?}"))?;
    let parse = |v: &str| v.trim().parse::<f64>().map_err(|e| format!("{v:?}: {e}"));
    let (w, h) = (parse(w)?, parse(h)?);
    if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
        return Err("the display's sides must be positive".into());
    }
    Ok([w, h])
}

/// `X,Y,Z` in metres (the earlier `--head`).
pub fn head(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|v| v.trim().parse::<f64>().map_err(|e| format!("{v:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|v| v.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!("expected X,Y,Z in metres, got {s:?}")),
    }
}

/// `W×H` in millimetres, as every tool gives a display's size; in metres.
fn display_mm(s: &str) -> Result<[f64; 2], String> {
    let [w, h] = display(s).map_err(|e| e.replace("in metres", "in mm"))?;
    Ok([w / 1000.0, h / 1000.0])
}

/// `X,Y,Z` in millimetres, as every tool gives a position in the display's frame; in metres.
pub fn head_mm(s: &str) -> Result<[f64; 3], String> {
    let [x, y, z] = head(s).map_err(|e| e.replace("in metres", "in mm"))?;
    Ok([x / 1000.0, y / 1000.0, z / 1000.0])
}

/// A snow line: finite metres.
fn snow_line(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v.abs() < 1e6 => Ok(v),
        _ => Err(format!("{s:?} is not a snow line: metres, e.g. 1800")),
    }
}

/// A vertical scale: a positive, finite factor.
pub fn vertical_scale(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "{s:?} is not a vertical scale: a factor above 0 (1: true heights)"
        )),
    }
}

/// Arguments of `penmodel render`.
#[derive(clap::Args)]
#[command(
    group(clap::ArgGroup::new("tracked_display").args(["display_mm", "display"])),
    group(clap::ArgGroup::new("tracked_head").args(["head_mm", "head"])),
    after_help = "Examples (from the repository's folder):\n  \
    penmodel render modeler/examples/04-volcano.json --png volcano.png --size 1280x720\n  \
    penmodel render modeler/examples/04-volcano.json --png a.png --size 640x360 --stereo anaglyph --tilt 20\n  \
    penmodel render modeler/examples/04-volcano.json --png t.png --size 640x360 --display-mm 600x340 --head-mm 0,-150,500"
)]
pub struct Args {
    /// The document (JSON). A pending journal beside it is replayed, read-only.
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// The frame as a PNG.
    #[arg(long, value_name = "OUT.png")]
    png: PathBuf,
    /// Frame size in pixels.
    #[arg(long, value_name = "WxH", value_parser = size, default_value = "1280x720")]
    size: (u32, u32),
    /// Stereo mode.
    #[arg(long, value_enum, default_value = "none")]
    stereo: StereoArg,
    /// How the terrain is coloured and lit (docs/renderer.md, "The land look").
    #[arg(long, value_enum, default_value = "land")]
    look: LookArg,
    /// Land look: the snow line, metres.
    #[arg(long, value_name = "M", value_parser = snow_line)]
    snow_line: Option<f64>,
    /// Orbit camera: angle around the terrain's centre, degrees (0 = from the south, 90 = east).
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    azimuth: f64,
    /// Orbit camera: angle above the ground, degrees.
    #[arg(long, default_value_t = 35.0, allow_negative_numbers = true)]
    elevation: f64,
    /// Orbit camera: distance to the terrain's centre, metres (default: the whole ground in view).
    #[arg(long)]
    distance: Option<f64>,
    /// Orbit camera: vertical field of view, degrees.
    #[arg(long, default_value_t = 45.0)]
    fov: f64,
    /// Tilt of the ground plane towards the viewer, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    tilt: f64,
    /// Vertical scale of the heights (exaggeration; 1: true heights).
    #[arg(long, default_value_t = 1.0, value_parser = vertical_scale, alias = "exaggeration", allow_negative_numbers = true)]
    vertical_scale: f64,
    /// Tracked view instead of the orbit camera: the display's size in mm; the terrain is fitted
    /// onto it.
    #[arg(long, value_name = "WxH", value_parser = display_mm, requires = "tracked_head")]
    display_mm: Option<[f64; 2]>,
    /// Earlier spelling of --display-mm, in metres.
    #[arg(long, value_name = "WxH", value_parser = display, requires = "tracked_head", hide = true)]
    display: Option<[f64; 2]>,
    /// Tracked view: the head in the display's frame, mm from its centre (x right, y up the
    /// display, z out of it towards the viewer).
    #[arg(long, value_name = "X,Y,Z", value_parser = head_mm, allow_hyphen_values = true, requires = "tracked_display")]
    head_mm: Option<[f64; 3]>,
    /// Earlier spelling of --head-mm, in metres.
    #[arg(long, value_name = "X,Y,Z", value_parser = head, allow_hyphen_values = true, requires = "tracked_display",
          hide = true)]
    head: Option<[f64; 3]>,
    /// Leave out the figures and region boundaries.
    #[arg(long)]
    no_overlays: bool,
    /// Shade by insolation (seed 002) for a sun at azimuth AZ (degrees from +x towards +y) and
    /// elevation EL (0, 90]: 0.8·direct (shadows exactly dark) + 0.2·sky view over 32 azimuths.
    #[arg(long, value_name = "AZ,EL", value_parser = crate::analyze::parse_sun, allow_hyphen_values = true)]
    sun: Option<(f64, f64)>,
    /// Overlay the ridge and valley areas (seed 002, `analyze`'s default thresholds): the valley
    /// network (along the flow through valley cells) in blue, the ridge cells (no drop but their
    /// own passes) in yellow, row by row, and the document's ridgelines and trees in orange.
    #[arg(long)]
    areas: bool,
    /// One line of text at the top left.
    #[arg(long, default_value = "")]
    mode: String,
    /// Also show the frame in a window until it is closed (or Escape is pressed); without a
    /// display this says so and carries on.
    #[arg(long)]
    window: bool,
    /// Also write a turntable of N frames (one turn around the terrain) to the folder given by
    /// --frames: frame_NNNNN.png and animation.png (APNG).
    #[arg(long, value_name = "N", requires = "frames", value_parser = clap::value_parser!(u32).range(1..=3600))]
    turntable: Option<u32>,
    /// The folder for --turntable.
    #[arg(long, value_name = "DIR", requires = "turntable")]
    frames: Option<PathBuf>,
    /// Draw every tree in full (level of detail off; seed 004).
    #[arg(long)]
    full_trees: bool,
    /// Render the frame N times more and print the median time and the trees' polygons
    /// (`render: M ms median of N, trees: T, polygons: P`), for comparing renderers.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeat: Option<u32>,
    /// The terrain's level of detail: the largest error, in pixels, a coarser level of the
    /// heightfield may make on screen; 0 draws every cell (docs/renderer.md).
    #[arg(long, value_name = "PX", default_value_t = penmodel_render::DEFAULT_LOD_PIXELS, value_parser = lod_error)]
    pub lod_error: f32,
}

/// A `--lod-error` value: finite pixels, at least 0.
pub fn lod_error(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("'{s}' is not a number of pixels"))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "--lod-error must be a finite number of pixels at least 0, not {s}"
        ))
    }
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let (editor, _) = Editor::open_read_only(&args.doc)?;
    let map = editor.heightmap();
    let grid = editor.document().grid;
    let extent = [grid.width(), grid.height()];
    let view = match (args.display_mm.or(args.display), args.head_mm.or(args.head)) {
        (Some(display), Some(head)) => {
            let mut t = Tracked::fit(display, extent, head[2]);
            t.head = head;
            View::Tracked(t)
        }
        _ => {
            let mut o = Orbit::overview(extent, args.azimuth.to_radians(), args.elevation.to_radians());
            o.fov_y = args.fov.to_radians();
            if let Some(d) = args.distance {
                o.distance = d;
            }
            View::Orbit(o)
        }
    };
    let overlays = if args.no_overlays {
        Vec::new()
    } else {
        penmodel::picture::document_overlays(editor.document())
    };
    let (_, hi) = map.range();
    // The rivers' and lakes' water, drawn flat at its level.
    let water: Vec<(String, penmodel_terrain::export::Mesh)> = editor
        .water()
        .filter(|w| w.any())
        .map(|w| vec![("water".to_string(), w.mesh(map.cell_size()))])
        .unwrap_or_default();
    let mut scene = Scene::new(
        map,
        Camera {
            view,
            tilt: args.tilt.to_radians(),
        },
    );
    let mut overlays = overlays;
    if args.areas {
        overlays.extend(ridge_overlays(editor.document(), map));
    }
    let light = match args.sun {
        Some((az, el)) => {
            let sun = SunPosition::degrees(az, el, "--sun").map_err(|e| anyhow::anyhow!(e))?;
            let field = Field::of(map);
            Some(sun::insolation(&sun::direct(field, sun), &sun::sky_view(field, 32)))
        }
        None => None,
    };
    scene.light_map = light.as_deref();
    scene.overlays = &overlays;
    scene.rocks = editor.rocks().meshes();
    scene.water = &water;
    // The document's trees, with level of detail from this camera (crate::forest).
    scene.trees = editor.trees().trees();
    if args.full_trees {
        scene.tree_lod = None;
    }
    scene.mode = &args.mode;
    scene.vertical_scale = args.vertical_scale as f32;
    scene.terrain_lod = args.lod_error;
    match args.look {
        LookArg::Classic => scene.style.ramp_top = ramp_top(hi),
        LookArg::Land => {
            scene.style = render::Style::land();
            // One frame: the light on the heightmap's own grid.
            scene.style.light_cells = 0;
            scene.style.sky_directions = 32;
            if let Some(m) = args.snow_line {
                scene.style.snow_line = m as f32;
            }
        }
    }
    scene.stereo = match args.stereo {
        StereoArg::None => Stereo::None,
        StereoArg::Anaglyph => Stereo::Anaglyph,
        StereoArg::SideBySide => Stereo::SideBySide,
    };
    let (w, h) = args.size;
    let mut frame = Frame::new(w, h)?;
    let mut renderer = Renderer::new();
    let stats = renderer.render(&scene, &mut frame)?;
    if stats.skipped_vertices > 0 {
        bail!("{} heights are not finite", stats.skipped_vertices);
    }
    if let Some(n) = args.repeat {
        // The first frame above baked the simplified shapes' textures; these are steady frames.
        let mut ms: Vec<f64> = (0..n)
            .map(|_| {
                let t = std::time::Instant::now();
                renderer
                    .render(&scene, &mut frame)
                    .map(|_| t.elapsed().as_secs_f64() * 1e3)
            })
            .collect::<Result<_, _>>()?;
        ms.sort_by(f64::total_cmp);
        let t = renderer.tree_stats();
        pen_host::outln!(
            "render: {:.2} ms median of {n}, trees: {}, polygons: {}",
            ms[ms.len() / 2],
            t.trees,
            t.total_polygons()
        );
    }
    output::write_png(&frame, &args.png)?;
    pen_host::outln!(
        "{} × {} frame of {} × {} cells written to {}",
        w,
        h,
        map.cols(),
        map.rows(),
        args.png.display()
    );
    if let (Some(n), Some(dir)) = (args.turntable, &args.frames) {
        let mut seq = output::Sequence::create(dir, 25)?;
        let mut renderer = Renderer::new();
        let mut turn = frame.clone();
        for i in 0..n {
            let mut s = scene.clone();
            if let View::Orbit(o) = &mut s.camera.view {
                o.azimuth += std::f64::consts::TAU * f64::from(i) / f64::from(n);
            }
            renderer.render(&s, &mut turn)?;
            seq.push(&turn)?;
        }
        if let Some(anim) = seq.finish()? {
            pen_host::outln!("{n} frames and {} written", anim.display());
        }
    }
    if args.window {
        show(frame);
    }
    Ok(())
}

/// Shows `frame` until the window is closed or Escape is pressed.
fn show(frame: Frame) {
    let mut viewer = match output::Viewer::open("penmodel render", frame.width(), frame.height()) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("penmodel: no window: {e}");
            return;
        }
    };
    if viewer.show(frame).is_err() {
        return;
    }
    while viewer.is_open() {
        match viewer.poll() {
            Some(output::ViewerEvent::Key(k)) if k == "Escape" || k == "q" => break,
            Some(_) => {}
            None => std::thread::sleep(std::time::Duration::from_millis(20)),
        }
    }
}

/// The ramp's top for a terrain whose highest point is `hi` metres: snow on the highest tenth.
pub fn ramp_top(hi: f32) -> f32 {
    if hi > 0.0 { hi / 0.9 } else { 1.0 }
}

/// Valley colour of `--areas`.
const VALLEY_COLOUR: render::Rgba = [40, 110, 230, 255];
/// Ridgeline colour of `--areas`.
const RIDGE_COLOUR: render::Rgba = [245, 150, 30, 255];
/// Colour of `--areas`' ridge cells.
const RIDGE_AREA_COLOUR: render::Rgba = [250, 215, 70, 255];

/// `--areas`: the valley network as draped lines along the rain's flow through valley cells
/// (one line from each valley cell no valley cell flows into, down to where the flow leaves the
/// valley cells), the ridge cells as runs along each row (a lone cell a dot), and the document's
/// ridgelines and trees' segments at their elevations.
fn ridge_overlays(doc: &penmodel_terrain::Document, map: &penmodel_terrain::Heightmap) -> Vec<render::Overlay> {
    use penmodel_terrain::ridge::rain::{self, Classes, STOP};
    let (cols, rows, cell) = (map.cols(), map.rows(), map.cell_size());
    let next = rain::directions(map.heights(), cols, rows, cell);
    let (counts, longest) = (rain::accumulate(&next), rain::longest_paths(&next));
    let valley = |i: usize| Classes::DEFAULT.is_valley(counts[i], longest[i]);
    let mut fed = vec![false; next.len()];
    for (i, &n) in next.iter().enumerate() {
        if n != STOP && valley(i) {
            fed[n as usize] = true;
        }
    }
    let centre = |i: u32| [(f64::from(i % cols) + 0.5) * cell, (f64::from(i / cols) + 0.5) * cell];
    let mut out = Vec::new();
    for (start, &is_fed) in fed.iter().enumerate() {
        if !valley(start) || is_fed {
            continue;
        }
        let mut points = vec![centre(start as u32)];
        let mut i = start as u32;
        while next[i as usize] != STOP && valley(next[i as usize] as usize) {
            i = next[i as usize];
            points.push(centre(i));
        }
        if points.len() > 1 {
            out.push(render::Overlay {
                points,
                closed: false,
                colour: VALLEY_COLOUR,
                width: 2.0,
                height: None,
            });
        }
    }
    let ridge = Classes::DEFAULT.ridges(&counts, &next);
    for (r, row) in ridge.chunks(cols as usize).enumerate() {
        let mut c = 0;
        while c < row.len() {
            if row[c] == 0.0 {
                c += 1;
                continue;
            }
            let start = c;
            while c < row.len() && row[c] > 0.0 {
                c += 1;
            }
            let at = |c: usize| centre(r as u32 * cols + c as u32);
            out.push(render::Overlay {
                points: if c - start == 1 {
                    vec![at(start)]
                } else {
                    vec![at(start), at(c - 1)]
                },
                closed: false,
                colour: RIDGE_AREA_COLOUR,
                width: 1.0,
                height: None,
            });
        }
    }
    if let Some(r) = &doc.ridges
        && let Ok(skeletons) = penmodel_terrain::ridge::layer::skeletons(r)
    {
        for (_, s) in skeletons {
            for [a, b] in s.edges {
                let (p, q) = (s.nodes[a as usize], s.nodes[b as usize]);
                out.push(render::Overlay {
                    points: vec![[p[0], p[1]], [q[0], q[1]]],
                    closed: false,
                    colour: RIDGE_COLOUR,
                    width: 3.0,
                    height: None,
                });
            }
        }
    }
    out
}
