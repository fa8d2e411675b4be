//! `penmodel analyze`: maps read off a document's terrain (seed 002 §3): rain pass counts and the
//! ridge and valley areas they give, direct sunlight, sky view and insolation. Each map is written
//! as raw float32 (rows × cols, little-endian, row-major, like `generate --raw`) or, for a name
//! ending in `.png`, as a 16-bit grayscale PNG (docs/ridgelines.md says what each holds).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::export;
use penmodel_terrain::fluvial::{measure, route};
use penmodel_terrain::ridge::rain::{self, Classes};
use penmodel_terrain::ridge::sun::{self, Field, Sun};
use penmodel_terrain::{Heightmap, ridge::RidgeError};

/// Arguments of `penmodel analyze`: at least one map.
#[derive(clap::Args)]
#[command(
    group(clap::ArgGroup::new("maps").args(["flow", "ridges", "valleys", "direct", "sky", "insolation", "hillshade", "area", "directions", "json"]).required(true).multiple(true)),
    after_help = "Give at least one map. A FILE ending in .png is a 16-bit PNG, any other raw float32 (rows × cols).\n\
    Examples (from the repository's folder):\n  \
    penmodel analyze modeler/examples/ridges/ridgelines.json --flow flow.png --valleys valleys.f32\n  \
    penmodel analyze modeler/examples/ridges/ridgelines.json --sun 135,25 --direct sun.png --sky sky.png --insolation ins.f32\n  \
    penmodel analyze modeler/examples/04-volcano.json --hillshade volcano-shade.png\n  \
    penmodel analyze modeler/examples/04-volcano.json --json --area area.png --directions d8.png"
)]
pub struct Args {
    /// The document (JSON). A pending journal beside it is replayed, read-only.
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// Rain pass counts: per cell, the drops (one per cell) that pass through it. The PNG shows log2(1 + count).
    #[arg(long, value_name = "FILE")]
    flow: Option<PathBuf>,
    /// Ridge areas: 1 where at most --ridge-max drops pass and the cell sheds water, else 0.
    #[arg(long, value_name = "FILE")]
    ridges: Option<PathBuf>,
    /// Valley areas: 1 where at least --valley-min drops pass, and --valley-convergence times the drops of the longest path there (water gathers, not a flank), else 0.
    #[arg(long, value_name = "FILE")]
    valleys: Option<PathBuf>,
    /// A cell passed by at most this many drops (its own included) is ridge.
    #[arg(long, value_name = "N", default_value_t = Classes::DEFAULT.ridge_max)]
    ridge_max: u32,
    /// A cell passed by at least this many drops is valley.
    #[arg(long, value_name = "N", default_value_t = Classes::DEFAULT.valley_min)]
    valley_min: u32,
    /// A valley cell's count is at least this many times its longest path's: 1 is the seed's count alone, which calls the lower part of any long plane flank valley.
    #[arg(long, value_name = "K", default_value_t = Classes::DEFAULT.valley_convergence, value_parser = clap::value_parser!(u32).range(1..))]
    valley_convergence: u32,
    /// The sun: azimuth in degrees from the grid's +x axis towards +y, elevation above the horizon in degrees (0, 90].
    #[arg(long, value_name = "AZ,EL", value_parser = parse_sun, allow_hyphen_values = true)]
    sun: Option<(f64, f64)>,
    /// Direct sunlight (needs --sun): Lambert's cos of the angle to the sun where the sun is above the cell's horizon, exactly 0 in shadow.
    #[arg(long, value_name = "FILE")]
    direct: Option<PathBuf>,
    /// Sky view fraction 0..1: 1 − mean over --sky-directions azimuths of sin² of the horizon angle.
    #[arg(long, value_name = "FILE")]
    sky: Option<PathBuf>,
    /// Insolation (needs --sun): 0.8·direct + 0.2·sky.
    #[arg(long, value_name = "FILE")]
    insolation: Option<PathBuf>,
    /// Hillshade: Lambert's cos of the angle to the sun (--sun, default 225,45: from the map's upper left) with no shadows, 0..1; the terrain's shape at a glance.
    #[arg(long, value_name = "FILE")]
    hillshade: Option<PathBuf>,
    /// Drainage area, m², by D8 on the depression-filled terrain (docs/erosion.md). The PNG shows log10 of it.
    #[arg(long, value_name = "FILE")]
    area: Option<PathBuf>,
    /// Flow direction: each cell's D8 receiver as 1 (east) to 8 counter-clockwise (45° steps), 0 at the grid's edge.
    #[arg(long, value_name = "FILE")]
    directions: Option<PathBuf>,
    /// Print the drainage signatures (area_tau, hack_h, slope_mode_share, pits, pit_depth_max; docs/erosion.md) as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Azimuths of the sky view's horizon sweeps.
    #[arg(long, value_name = "K", default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=4096))]
    sky_directions: u32,
}

/// `AZ,EL` in degrees (`--sun`); `render --sun` reads it too.
pub(crate) fn parse_sun(s: &str) -> Result<(f64, f64), String> {
    let (a, e) = s.split_once(',').ok_or("give AZ,EL in degrees, e.g. 135,25")?;
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("{t:?} is not a number of degrees"))
    };
    Ok((num(a)?, num(e)?))
}

fn write_map(map: &Heightmap, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        export::write_png(map, &mut bytes).map(|_| ())
    } else {
        export::write_raw(map, &mut bytes)
    }
    .with_context(|| format!("cannot export {}", path.display()))?;
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes `values` (one per cell) to `path`; `png` replaces them for a PNG. With `json` (stdout
/// is the JSON) it says so on stderr.
fn write(json: bool, like: &Heightmap, path: &Option<PathBuf>, values: &[f32], png: impl Fn(f32) -> f32) -> Result<()> {
    let Some(path) = path else { return Ok(()) };
    let is_png = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let v: Vec<f32> = if is_png {
        values.iter().map(|&x| png(x)).collect()
    } else {
        values.to_vec()
    };
    let map = Heightmap::from_heights(like.cols(), like.rows(), like.cell_size(), v)
        .context("a map of another size than the grid")?;
    write_map(&map, path)?;
    if json {
        eprintln!("wrote {}", path.display());
    } else {
        pen_host::outln!("wrote {}", path.display());
    }
    Ok(())
}

/// The drainage maps and signatures (`--area`, `--directions`, `--json`).
fn drainage(map: &Heightmap, water: Option<&penmodel_terrain::river::layer::Water>, args: &Args) -> Result<()> {
    if args.area.is_some() || args.directions.is_some() {
        let h: Vec<f64> = map
            .heights()
            .iter()
            .map(|&v| if v.is_finite() { f64::from(v) } else { 0.0 })
            .collect();
        let mut w = route::Routing::new(map.cols() as usize, map.rows() as usize);
        w.route(&h);
        let cell2 = map.cell_size() * map.cell_size();
        let area: Vec<f32> = w.area.iter().map(|&a| (a * cell2) as f32).collect();
        write(args.json, map, &args.area, &area, |a| a.log10())?;
        let cols = map.cols() as i64;
        let dirs: Vec<f32> = (0..h.len())
            .map(|i| {
                let r = i64::from(w.receiver[i]);
                let (dc, dr) = (r % cols - i as i64 % cols, r / cols - i as i64 / cols);
                // Counter-clockwise from east, y (rows) pointing up the map.
                let angle = f64::atan2(-dr as f64, dc as f64).to_degrees().rem_euclid(360.0);
                if (dc, dr) == (0, 0) {
                    0.0
                } else {
                    1.0 + (angle / 45.0).round() as f32 % 8.0
                }
            })
            .collect();
        write(args.json, map, &args.directions, &dirs, |d| d)?;
    }
    if args.json {
        // Water the user drew (rivers and their lakes) is not a pit.
        let wet: Option<Vec<bool>> = water.map(|w| w.level.iter().map(|l| !l.is_nan()).collect());
        let s = measure::signatures(map, wet.as_deref());
        pen_host::outln!("{}", serde_json::to_string_pretty(&s)?);
    }
    Ok(())
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let sun = match args.sun {
        Some((az, el)) => Some(Sun::degrees(az, el, "--sun").map_err(|e: RidgeError| anyhow::anyhow!(e))?),
        None => None,
    };
    if sun.is_none() && (args.direct.is_some() || args.insolation.is_some()) {
        bail!("--direct and --insolation need the sun's position: give --sun AZ,EL");
    }
    let (editor, _) = Editor::open_read_only(&args.doc)?;
    let map = editor.heightmap();
    drainage(map, editor.water(), args)?;
    let field = Field::of(map);
    if args.flow.is_some() || args.ridges.is_some() || args.valleys.is_some() {
        let t = Instant::now();
        let next = rain::directions(field.z, field.cols, field.rows, field.cell);
        let counts = rain::accumulate(&next);
        eprintln!("rain counts: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
        let as_f32: Vec<f32> = counts.iter().map(|&n| n as f32).collect();
        write(args.json, map, &args.flow, &as_f32, |n| (1.0 + n).log2())?;
        let classes = Classes {
            ridge_max: args.ridge_max,
            valley_min: args.valley_min,
            valley_convergence: args.valley_convergence,
        };
        write(args.json, map, &args.ridges, &classes.ridges(&counts, &next), |v| v)?;
        write(
            args.json,
            map,
            &args.valleys,
            &classes.valleys(&counts, &rain::longest_paths(&next)),
            |v| v,
        )?;
    }
    let direct = match sun {
        Some(s) if args.direct.is_some() || args.insolation.is_some() => {
            let t = Instant::now();
            let d = sun::direct(field, s);
            eprintln!("direct light: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
            Some(d)
        }
        _ => None,
    };
    let sky = if args.sky.is_some() || args.insolation.is_some() {
        let t = Instant::now();
        let s = sun::sky_view(field, args.sky_directions);
        eprintln!(
            "sky view ({} azimuths): {:.1} ms",
            args.sky_directions,
            t.elapsed().as_secs_f64() * 1e3
        );
        Some(s)
    } else {
        None
    };
    if let Some(d) = &direct {
        write(args.json, map, &args.direct, d, |v| v)?;
    }
    if let Some(s) = &sky {
        write(args.json, map, &args.sky, s, |v| v)?;
    }
    if let (Some(d), Some(s)) = (&direct, &sky) {
        write(args.json, map, &args.insolation, &sun::insolation(d, s), |v| v)?;
    }
    if args.hillshade.is_some() {
        let light = match sun {
            Some(s) => s,
            None => Sun::degrees(225.0, 45.0, "the hillshade's light").map_err(|e: RidgeError| anyhow::anyhow!(e))?,
        };
        write(args.json, map, &args.hillshade, &sun::hillshade(field, light), |v| v)?;
    }
    Ok(())
}
