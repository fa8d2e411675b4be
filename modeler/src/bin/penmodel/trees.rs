//! `penmodel trees`: the fractal trees of seed 004 on their own — node and polygon counts per
//! roughness Q against the seed's law (`stats`, the default), a tree or grove as a mesh (`mesh`),
//! a species fitted to a front and a side silhouette (`fit`), and the seed's 30-tree scene rendered
//! with level of detail off and on (`scene`). docs/trees.md.

mod scene;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::DAffine3;
use penmodel_terrain::document::{Grove, GroveSpecies, IfsMap, Sway, Wind};
use penmodel_terrain::export::{self, Mesh};
use penmodel_terrain::trees::fit::{self, Options};
use penmodel_terrain::trees::lod::{self, law};
use penmodel_terrain::trees::nodes::STOP;
use penmodel_terrain::trees::silhouette::Image;
use penmodel_terrain::trees::{Drawn, NodeTree, Preset, Species, planted, wind};
use penmodel_terrain::{persist, validate};
use serde_json::{Value, json};

use crate::out::write;

/// Arguments of `penmodel trees`.
#[derive(clap::Args)]
#[command(
    args_conflicts_with_subcommands = true,
    after_help = "Without a subcommand: the counts per Q (as `trees stats`).\n\
    Examples:\n  \
    penmodel trees --preset table-3.1 --q 0.02,0.05,0.1,0.2 --json -\n  \
    penmodel trees mesh --preset oak --height 12 --q 0.05 --glb oak.glb\n  \
    penmodel trees mesh --grove 30 --density 200 --mix oak:2,fir:1 --obj grove.obj\n  \
    penmodel trees fit front.png side.png --json fit.json\n  \
    penmodel trees scene --trees 30 --bench --json"
)]
pub struct Args {
    #[command(subcommand)]
    command: Option<Sub>,
    #[command(flatten)]
    stats: StatsArgs,
}

#[derive(clap::Subcommand)]
enum Sub {
    /// Nodes, simplified shapes and polygons per roughness Q against the law (M/(M−1))·Q^(ln M/ln λ).
    #[command(after_help = "Examples:\n  \
        penmodel trees stats --preset table-3.1 --q 0.02,0.05,0.1,0.2\n  \
        penmodel trees stats --maps my-maps.json --json -")]
    Stats(StatsArgs),
    /// A tree or a grove on flat ground as OBJ, PLY or binary glTF (coloured bark and leaves).
    #[command(after_help = "Give at least one output: --obj, --ply or --glb.\n\
        Examples:\n  \
        penmodel trees mesh --preset table-3.1 --obj tree.obj                 # the full tree, 10 m\n  \
        penmodel trees mesh --preset fir --q 0.1 --ply fir.ply                # at Q = 0.1, with cards\n  \
        penmodel trees mesh --wind 2:0.3,6:0.8 --t 0.5 --glb sway.glb         # swaying, at t = 0.5 s\n  \
        penmodel trees mesh --grove 25 --density 300 --mix oak,cypress --seed 4 --glb grove.glb")]
    Mesh(MeshArgs),
    /// Fit a species' maps to a front and a side silhouette (PNG) by normalised cross-correlation.
    #[command(
        after_help = "The silhouettes: the tree dark on a light ground or light on a dark one \
        (any PNG colour type); each is framed by its bounding box.\n\
        Examples:\n  \
        penmodel trees fit front.png side.png\n  \
        penmodel trees fit front.png side.png --iterations 50 --json -"
    )]
    Fit(FitArgs),
    /// The seed's scene: Table 3.1 trees on example 1's terrain, rendered with level of detail
    /// off and on; polygons, frame times (--bench) and the image difference.
    #[command(after_help = "Examples:\n  \
        penmodel trees scene --trees 30 --bench --json\n  \
        penmodel trees scene --png scene/                   # scene/full.png and scene/lod.png")]
    Scene(scene::SceneArgs),
}

/// Which species.
#[derive(clap::Args)]
struct SpeciesArgs {
    /// A preset: table-3.1, sample-3.2, cypress, oak or fir.
    #[arg(long, default_value = "table-3.1", conflicts_with = "maps")]
    preset: String,
    /// The maps as a JSON list of {"y", "s", "theta_z", "theta_y"} (degrees), instead of a preset.
    #[arg(long, value_name = "FILE.json")]
    maps: Option<PathBuf>,
}

#[derive(clap::Args)]
struct StatsArgs {
    #[command(flatten)]
    species: SpeciesArgs,
    /// Roughness values Q in (0, 1] (default: 0.02 to 0.2 in seven steps).
    #[arg(long, value_name = "Q,Q,…", value_delimiter = ',')]
    q: Vec<f64>,
    /// The counts as JSON (docs/trees.md); `-` for stdout.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("outputs").args(["obj", "ply", "glb"]).required(true).multiple(true)))]
struct MeshArgs {
    #[command(flatten)]
    species: SpeciesArgs,
    /// The tree's height, metres.
    #[arg(long, default_value_t = 10.0)]
    height: f64,
    /// Roughness Q in (0, 1]: groups no larger than Q·height become crossed cards (untextured,
    /// leaf-coloured); at or below 0.02 the full tree.
    #[arg(long, default_value_t = STOP)]
    q: f64,
    /// Sway per generation from the trunk, AMPLITUDE:FREQUENCY[:REST] (degrees, hertz, degrees).
    #[arg(long, value_name = "A:F,…", value_delimiter = ',', allow_hyphen_values = true)]
    wind: Vec<String>,
    /// The direction the wind blows towards, degrees from +x towards +y.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    wind_direction: f64,
    /// The time of the sway, seconds.
    #[arg(long, default_value_t = 0.0)]
    t: f64,
    /// A grove in a circle of this radius (metres) instead of one tree.
    #[arg(long, value_name = "RADIUS")]
    grove: Option<f64>,
    /// The grove's trees per hectare.
    #[arg(long, default_value_t = 200.0, requires = "grove")]
    density: f64,
    /// The grove's presets and weights, PRESET[:WEIGHT],… (default: --preset alone).
    #[arg(long, value_name = "P:W,…", value_delimiter = ',', requires = "grove")]
    mix: Vec<String>,
    /// The grove's seed (the tree's turn for one tree).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Wavefront OBJ (vertex colours after the positions); `-` for stdout.
    #[arg(long, value_name = "FILE")]
    obj: Option<PathBuf>,
    /// Binary PLY (colours as sRGB bytes).
    #[arg(long, value_name = "FILE")]
    ply: Option<PathBuf>,
    /// Binary glTF (COLOR_0).
    #[arg(long, value_name = "FILE")]
    glb: Option<PathBuf>,
}

#[derive(clap::Args)]
struct FitArgs {
    /// The front silhouette (looking along −Z).
    #[arg(value_name = "FRONT.png")]
    front: PathBuf,
    /// The side silhouette (looking along +X).
    #[arg(value_name = "SIDE.png")]
    side: PathBuf,
    /// Most gradient steps of each ascent.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=1000))]
    iterations: u32,
    /// The longest the ascents may take together, in seconds; past it the best result so far is kept and a warning says so.
    #[arg(long, value_name = "SECS", default_value_t = fit::BUDGET.as_secs_f64(), value_parser = parse_secs)]
    time_limit: f64,
    /// How many of the best-matching presets an ascent starts from (the best result is kept).
    #[arg(long, default_value_t = fit::STARTS as u32, value_parser = clap::value_parser!(u32).range(1..=4))]
    starts: u32,
    /// The result as JSON (the maps usable as --maps or a document tree's "maps"); `-` for stdout.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// Prints a summary line, on stderr when `json` goes to stdout.
fn say(json: Option<&Path>, line: &str) -> Result<()> {
    if json == Some(Path::new("-")) {
        eprintln!("{line}");
    } else {
        pen_host::outln!("{line}");
    }
    Ok(())
}

fn check_q(q: f64, flag: &str) -> Result<()> {
    if !(q > 0.0 && q <= 1.0) {
        bail!("{flag}: Q = {q} is outside (0, 1]");
    }
    Ok(())
}

fn species(args: &SpeciesArgs) -> Result<Species> {
    match &args.maps {
        Some(path) => {
            let bytes = penmodel_terrain::input::read_input(path, penmodel_terrain::input::MAX_INPUT_BYTES)
                .with_context(|| format!("cannot read {}", path.display()))?;
            let text = String::from_utf8(bytes).with_context(|| format!("{}: not UTF-8 text", path.display()))?;
            let maps: Vec<IfsMap> = serde_json::from_str(persist::strip_bom(&text)).with_context(|| {
                format!(
                    "{}: not a list of maps ({{\"y\", \"s\", \"theta_z\", \"theta_y\"}}, …)",
                    path.display()
                )
            })?;
            validate::species(&maps, "maps").with_context(|| format!("{}", path.display()))?;
            Ok(Species { maps })
        }
        None => match Preset::named(&args.preset) {
            Some(p) => Ok(Species::preset(p)),
            None => bail!(
                "--preset: unknown preset {:?}; the presets are {}",
                args.preset,
                Preset::names()
            ),
        },
    }
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    match &args.command {
        None => stats(&args.stats),
        Some(Sub::Stats(a)) => stats(a),
        Some(Sub::Mesh(a)) => mesh(a),
        Some(Sub::Fit(a)) => fit_run(a),
        Some(Sub::Scene(a)) => scene::run(a),
    }
}

/// The least-squares slope of ln N against ln Q.
fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0.ln()).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1.ln()).sum::<f64>() / n;
    let num: f64 = points.iter().map(|p| (p.0.ln() - mx) * (p.1.ln() - my)).sum();
    let den: f64 = points.iter().map(|p| (p.0.ln() - mx).powi(2)).sum();
    (den > 0.0).then(|| num / den)
}

fn stats(args: &StatsArgs) -> Result<()> {
    let s = species(&args.species)?;
    let qs = if args.q.is_empty() {
        vec![0.02, 0.03, 0.05, 0.07, 0.1, 0.14, 0.2]
    } else {
        args.q.clone()
    };
    for &q in &qs {
        check_q(q, "--q")?;
    }
    let tree = NodeTree::build(&s);
    let mut rows = Vec::new();
    let mut points = Vec::new();
    let mut lines = Vec::new();
    for &q in &qs {
        let mut d = Drawn::default();
        tree.draw(q, &DAffine3::IDENTITY, None, &mut d);
        let l = law(s.m(), s.lambda(), q);
        points.push((q, d.volume() as f64));
        // Each simplified shape is drawn as one polygon (the crossed polygon facing the eye).
        let polygons = d.polygons + d.impostors.len() as u64;
        rows.push(json!({
            "q": q, "nodes": d.nodes, "shapes": d.impostors.len(), "leaves": d.leaves,
            "volume": d.volume(), "law": l, "polygons": polygons, "triangles": d.mesh.indices.len() / 3,
        }));
        lines.push(format!(
            "Q {q:<5}: {:>6} nodes, {:>5} shapes, {:>6} leaves, volume {:>6} (law {:>7.0}, ratio {:.2}), {:>7} polygons",
            d.nodes,
            d.impostors.len(),
            d.leaves,
            d.volume(),
            l,
            d.volume() as f64 / l,
            polygons
        ));
    }
    let fitted = fitted_exponent(&points);
    if let Some(path) = &args.json {
        let v = json!({
            "m": s.m(), "lambda": s.lambda(), "law_exponent": s.law_exponent(), "dimension": s.dimension(),
            "fitted_exponent": fitted, "full": {"nodes": tree.nodes.len(), "polygons": tree.polygons()},
            "per_q": rows,
        });
        let mut text = serde_json::to_string(&v)?;
        text.push('\n');
        write(path, text.as_bytes())?;
    }
    let json = args.json.as_deref();
    say(
        json,
        &format!(
            "M = {}, λ = {:.3}: law exponent {:.3}, similarity dimension {:.3}; full tree {} nodes, {} polygons",
            s.m(),
            s.lambda(),
            s.law_exponent(),
            s.dimension(),
            tree.nodes.len(),
            tree.polygons()
        ),
    )?;
    for l in lines {
        say(json, &l)?;
    }
    if let Some(e) = fitted {
        say(json, &format!("fitted exponent of volume against Q: {e:.3}"))?;
    }
    Ok(())
}

fn parse_wind(specs: &[String], direction: f64) -> Result<Option<Wind>> {
    if specs.is_empty() {
        return Ok(None);
    }
    let mut generations = Vec::new();
    for s in specs {
        let parts: Vec<&str> = s.split(':').collect();
        let num = |v: &str| {
            v.trim().parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                anyhow::anyhow!("--wind: {s:?} is not AMPLITUDE:FREQUENCY[:REST] of finite numbers (e.g. 5:0.8)")
            })
        };
        match parts[..] {
            [a, f] => generations.push(Sway {
                amplitude: num(a)?,
                frequency: num(f)?,
                rest: 0.0,
            }),
            [a, f, r] => generations.push(Sway {
                amplitude: num(a)?,
                frequency: num(f)?,
                rest: num(r)?,
            }),
            _ => bail!("--wind: {s:?} is not AMPLITUDE:FREQUENCY[:REST] (e.g. 5:0.8)"),
        }
    }
    Ok(Some(Wind { direction, generations }))
}

fn parse_mix(specs: &[String], preset: &str) -> Result<Vec<GroveSpecies>> {
    if specs.is_empty() {
        return Ok(vec![GroveSpecies {
            preset: preset.to_owned(),
            weight: 1.0,
        }]);
    }
    specs
        .iter()
        .map(|s| {
            let (p, w) = s.split_once(':').unwrap_or((s, "1"));
            let weight = w
                .trim()
                .parse::<f64>()
                .map_err(|_| anyhow::anyhow!("--mix: {s:?} is not PRESET[:WEIGHT] (e.g. oak:2)"))?;
            Ok(GroveSpecies {
                preset: p.trim().to_owned(),
                weight,
            })
        })
        .collect()
}

fn mesh(args: &MeshArgs) -> Result<()> {
    check_q(args.q, "--q")?;
    // NaN made every vertex NaN and an invalid glTF (issue 47).
    for (flag, v) in [("--t", args.t), ("--wind-direction", args.wind_direction)] {
        if !v.is_finite() {
            bail!("{flag}: {v} is not a finite number");
        }
    }
    if !(args.height > 0.0 && args.height <= penmodel_terrain::trees::MAX_HEIGHT) {
        bail!(
            "--height: {} m is not above 0 and at most {} m",
            args.height,
            penmodel_terrain::trees::MAX_HEIGHT
        );
    }
    let wind = parse_wind(&args.wind, args.wind_direction)?;
    if let Some(w) = &wind {
        // The same checks as a document tree's wind.
        let mut check = penmodel_terrain::Document::new(penmodel_terrain::Grid {
            cols: 1,
            rows: 1,
            cell_size: 1.0,
        });
        check.trees.push(penmodel_terrain::document::Tree {
            at: [0.5, 0.5],
            height: 1.0,
            preset: None,
            maps: None,
            seed: 0,
            wind: Some(w.clone()),
        });
        validate::trees(&check).map_err(|e| anyhow::anyhow!("--wind: {}", e.defect))?;
    }
    // A grove is checked as a document's.
    let mut doc = penmodel_terrain::Document::new(penmodel_terrain::Grid {
        cols: 4096,
        rows: 4096,
        cell_size: 1.0,
    });
    let centre = [2048.0, 2048.0];
    let mut drawn = Drawn::default();
    // The simplified shapes as crossed cards, each from its own tree's box.
    let mut cards = Mesh::default();
    let what = match args.grove {
        Some(radius) => {
            if args.species.maps.is_some() {
                bail!("--maps: a grove mixes presets (--mix); give --preset or --mix");
            }
            if !(radius > 0.0 && radius < 2000.0) {
                bail!("--grove: a radius of {radius} m is not above 0 and below 2000 m");
            }
            let region: Vec<[f64; 2]> = (0..=48)
                .map(|k| {
                    let a = std::f64::consts::TAU * f64::from(k % 48) / 48.0;
                    [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
                })
                .collect();
            doc.groves.push(Grove {
                region,
                density: args.density,
                mix: parse_mix(&args.mix, &args.species.preset)?,
                height: args.height,
                seed: args.seed,
                wind: wind.clone(),
            });
            validate::groves(&doc).map_err(|e| anyhow::anyhow!("the grove: {e}"))?;
            // Flat ground at 0.
            let map = penmodel_terrain::Heightmap::from_heights(1, 1, 4096.0, vec![0.0])
                .ok_or_else(|| anyhow::anyhow!("a flat ground of one cell"))?;
            let forest = penmodel_terrain::trees::Forest::of(&doc, &map);
            for t in forest.trees() {
                // Around the origin.
                let mut t = t.clone();
                t.at = [t.at[0] - centre[0], t.at[1] - centre[1]];
                let first = drawn.impostors.len();
                t.draw(args.q, args.t, &mut drawn);
                append(&mut cards, &lod::cards(&t.nodes, &drawn.impostors[first..]));
            }
            format!("{} trees", forest.trees().len())
        }
        None => {
            let s = species(&args.species)?;
            let tree = NodeTree::build(&s);
            let place = DAffine3::from_rotation_y(planted::turn(args.seed))
                * DAffine3::from_scale(glam::DVec3::splat(args.height / tree.height));
            let pose = wind.as_ref().map(|w| wind::pose(w, args.t));
            tree.draw(args.q, &place, pose.as_ref(), &mut drawn);
            cards = lod::cards(&tree, &drawn.impostors);
            "1 tree".to_owned()
        }
    };
    let mut meshes: Vec<(&str, &Mesh)> = vec![("trees", &drawn.mesh)];
    if !cards.indices.is_empty() {
        meshes.push(("simplified shapes", &cards));
    }
    if let Some(path) = &args.obj {
        let mut bytes = b"# penmodel trees: X = x, Y = height, Z = y (metres); v x y z r g b (linear)\n".to_vec();
        export::write_meshes(meshes.iter().map(|(n, m)| (*n, *m)), &mut bytes)
            .with_context(|| format!("cannot export {}", path.display()))?;
        write(path, &bytes)?;
    }
    if let Some(path) = &args.ply {
        let mut bytes = Vec::new();
        export::write_ply(&meshes, &mut bytes).with_context(|| format!("cannot export {}", path.display()))?;
        write(path, &bytes)?;
    }
    if let Some(path) = &args.glb {
        let mut bytes = Vec::new();
        export::write_glb_meshes(&meshes, &mut bytes).with_context(|| format!("cannot export {}", path.display()))?;
        write(path, &bytes)?;
    }
    let line = format!(
        "{what} at Q = {}: {} polygons ({} triangles), {} simplified shapes (as crossed cards)",
        args.q,
        drawn.polygons,
        drawn.mesh.indices.len() / 3,
        drawn.impostors.len(),
    );
    let to_stdout = [&args.obj, &args.ply, &args.glb]
        .iter()
        .any(|p| p.as_deref() == Some(Path::new("-")));
    say(to_stdout.then_some(Path::new("-")), &line)?;
    Ok(())
}

/// Appends `src` to `dst`, numbering its vertices on.
fn append(dst: &mut Mesh, src: &Mesh) {
    let base = dst.positions.len() as u32;
    dst.positions.extend_from_slice(&src.positions);
    dst.normals.extend_from_slice(&src.normals);
    dst.colors.extend_from_slice(&src.colors);
    dst.indices.extend(src.indices.iter().map(|i| i + base));
}

fn read_silhouette(path: &Path) -> Result<Image> {
    let file = penmodel_terrain::input::open_input(path, penmodel_terrain::input::MAX_INPUT_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Image::read_png(std::io::BufReader::new(file)).with_context(|| format!("{}", path.display()))
}

fn maps_json(s: &Species) -> Value {
    serde_json::to_value(&s.maps).unwrap_or(Value::Null)
}

/// A `--time-limit`: positive seconds, at most a day.
fn parse_secs(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number of seconds"))?;
    if v.is_finite() && v > 0.0 && v <= 86_400.0 {
        Ok(v)
    } else {
        Err(format!("{s} s: give a time limit above 0 and at most 86400 s"))
    }
}

fn fit_run(args: &FitArgs) -> Result<()> {
    let front = read_silhouette(&args.front)?;
    let side = read_silhouette(&args.side)?;
    let f = fit::fit(
        &front,
        &side,
        Options {
            iterations: args.iterations as usize,
            starts: args.starts as usize,
            budget: std::time::Duration::from_secs_f64(args.time_limit),
        },
    )?;
    if f.out_of_time {
        eprintln!(
            "warning: the fit stopped at its time limit ({} s) and keeps the best result so far; give --time-limit more seconds or fewer --iterations/--starts",
            args.time_limit
        );
    }
    if let Some(path) = &args.json {
        let v = json!({
            "preset": f.preset.name(), "start": f.start, "reached": f.reached,
            "iterations": f.iterations, "out_of_time": f.out_of_time, "maps": maps_json(&f.species),
        });
        let mut text = serde_json::to_string(&v)?;
        text.push('\n');
        write(path, text.as_bytes())?;
    }
    let json = args.json.as_deref();
    say(json, &format!("preset {} (the best template)", f.preset.name()))?;
    say(
        json,
        &format!(
            "correlation front {:.3}, side {:.3} (from {:.3}, {:.3} in {} steps)",
            f.reached[0], f.reached[1], f.start[0], f.start[1], f.iterations
        ),
    )?;
    for (i, m) in f.species.maps.iter().enumerate() {
        say(
            json,
            &format!(
                "map {}: y {:.3}, s {:.3}, θz {:.1}°, θy {:.1}°",
                i + 1,
                m.y,
                m.s,
                m.theta_z,
                m.theta_y
            ),
        )?;
    }
    Ok(())
}
