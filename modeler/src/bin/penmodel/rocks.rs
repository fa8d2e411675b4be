//! `penmodel rocks`: the rock field of seed 001 on its own, for the seed's experiments — a field
//! image of `--size` cells, diagrams of `--radii` taking `--fractions` (or `--counts`), shapes by
//! `--preset` or coefficients; the result as JSON (docs/rocks.md), OBJ, glTF and a top view.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use penmodel_terrain::export;
use penmodel_terrain::rocks::place::{self, Placement};
use penmodel_terrain::rocks::{Amount, Layer, Recipe, RecipeError, Sampler, Shape, scatter, top_view};

mod json;

use crate::out::write;

/// The seed's shape presets (its table 1 and figs. 9–11).
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// Fig. 1: per diagram (r = 9, 3, 1) c_w = (0, .3, .3), (0, .3, .1), (.1, .1, .1) and
    /// c_h = (.3, .3, .1), (.3, .3, .1), (.3, 0, .1); with the default radii, also its fractions.
    Fig1,
    /// Figs. 9–10: c_w = 0, c_h = (.3, 0, .1).
    Plain,
    /// Fig. 11 (a): points move out, c_w1 = 0.4.
    Expand,
    /// Fig. 11 (b): points move in, c_w1 = −0.4.
    Contract,
    /// Fig. 11 (c): c_w1 = 0.2, c_w2 = 0.4.
    RandomWidths,
    /// Fig. 11 (d): c_h1 = 1.0.
    Tall,
    /// Fig. 11 (e): c_h1 = 0.1.
    Low,
    /// Fig. 11 (f): c_h1 = 0.3, c_h2 = 0.7.
    RandomHeights,
}

/// How seeds are thrown.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplerArg {
    /// Every cell tried once in random order: maximal (no room left for another seed).
    Saturate,
    /// The seed's darts: A·fill / (π(0.5r)²) throws (eq. 1).
    Darts,
}

/// Arguments of `penmodel rocks`.
#[derive(clap::Args)]
#[command(after_help = "Examples:\n  \
    penmodel rocks --png fig1.png                          # the seed's fig. 1 on 512 × 512 cells\n  \
    penmodel rocks --radii 9 --fractions 0.5 --preset tall --json tall.json --obj tall.obj\n  \
    penmodel rocks --size 256x256 --radii 6,2 --counts 40,400 --widths 0.2,0.4,0 --seed 7 --glb f.glb")]
pub struct Args {
    /// The field image in cells, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    size: (u32, u32),
    /// Poisson-disk radii in cells, one diagram each (default: the seed's fig. 1, 9,3,1).
    #[arg(long, value_name = "R,R,…", value_delimiter = ',', allow_hyphen_values = true)]
    radii: Vec<f64>,
    /// Area fraction A_s per radius, in the same order (default with the default radii: 0.2,0.24,0.56).
    #[arg(long, value_name = "F,F,…", value_delimiter = ',', conflicts_with = "counts")]
    fractions: Vec<f64>,
    /// Number of rocks per radius, instead of fractions.
    #[arg(long, value_name = "N,N,…", value_delimiter = ',')]
    counts: Vec<u32>,
    /// Shape coefficients from the seed (overridden by --widths and --heights).
    #[arg(long, value_enum, default_value = "fig1")]
    preset: Preset,
    /// Eq. 2's c_w1,c_w2,c_w3 for every diagram (sideways move, × r).
    #[arg(long, value_name = "C1,C2,C3", value_delimiter = ',', allow_hyphen_values = true)]
    widths: Vec<f64>,
    /// Eq. 3's c_h1,c_h2,c_h3 for every diagram (height, × r; 0 to 10).
    #[arg(long, value_name = "C1,C2,C3", value_delimiter = ',', allow_hyphen_values = true)]
    heights: Vec<f64>,
    /// Fail (exit 1, after writing the outputs) when a diagram cannot reach its amount; without it that is a warning.
    #[arg(long)]
    strict: bool,
    /// The random seed: the same seed, the same rocks.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// How seeds are thrown.
    #[arg(long, value_enum, default_value = "saturate")]
    sampler: SamplerArg,
    /// The darts' filling rate c_d (with --sampler darts).
    #[arg(long, default_value_t = 0.7)]
    fill: f64,
    /// Everything as JSON (docs/rocks.md); `-` for stdout.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// The rocks as Wavefront OBJ on flat ground (1 unit per cell, Y up).
    #[arg(long, value_name = "FILE")]
    obj: Option<PathBuf>,
    /// The rocks as binary glTF on flat ground (1 unit per cell, Y up).
    #[arg(long, value_name = "FILE")]
    glb: Option<PathBuf>,
    /// A top view: cells coloured by diagram, the gaps dark.
    #[arg(long, value_name = "FILE")]
    png: Option<PathBuf>,
    /// Pixels per cell in the top view (default: 1024 pixels across, at least 1 per cell).
    #[arg(long, value_name = "N")]
    png_scale: Option<u32>,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 512x512)"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}' is not WIDTHxHEIGHT (e.g. 512x512)"))
    };
    Ok((num(w)?, num(h)?))
}

/// Fig. 1's coefficients for its three diagrams (table 1), largest radius first: a diagram takes
/// the row of its radius's rank among the radii given (the largest the first row, the third
/// largest and smaller the last), whatever order the radii are listed in.
const FIG1: [([f64; 3], [f64; 3]); 3] = [
    ([0.0, 0.3, 0.3], [0.3, 0.3, 0.1]),
    ([0.0, 0.3, 0.1], [0.3, 0.3, 0.1]),
    ([0.1, 0.1, 0.1], [0.3, 0.0, 0.1]),
];

fn preset_shape(preset: Preset, rank: usize) -> Shape {
    let s = |widths, heights| Shape { widths, heights };
    match preset {
        Preset::Fig1 => {
            let (w, h) = FIG1[rank.min(2)];
            s(w, h)
        }
        Preset::Plain => s([0.0; 3], [0.3, 0.0, 0.1]),
        Preset::Expand => s([0.4, 0.0, 0.0], [0.3, 0.0, 0.0]),
        Preset::Contract => s([-0.4, 0.0, 0.0], [0.3, 0.0, 0.0]),
        Preset::RandomWidths => s([0.2, 0.4, 0.0], [0.3, 0.0, 0.0]),
        Preset::Tall => s([0.0; 3], [1.0, 0.0, 0.0]),
        Preset::Low => s([0.0; 3], [0.1, 0.0, 0.0]),
        Preset::RandomHeights => s([0.0; 3], [0.3, 0.7, 0.0]),
    }
}

fn ordinal(i: usize) -> String {
    let n = i + 1;
    let suffix = match (n % 10, n % 100) {
        (1, 11) | (2, 12) | (3, 13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// The recipe the flags describe; errors name the flag.
fn recipe(args: &Args) -> Result<Recipe> {
    let default_radii = args.radii.is_empty();
    let radii = if default_radii {
        vec![9.0, 3.0, 1.0]
    } else {
        args.radii.clone()
    };
    let amounts: Vec<Amount> = if !args.counts.is_empty() {
        if args.counts.len() != radii.len() {
            bail!(
                "--counts: give one count per radius ({} radii, {} counts)",
                radii.len(),
                args.counts.len()
            );
        }
        args.counts.iter().map(|&c| Amount::Count(c)).collect()
    } else if !args.fractions.is_empty() {
        if args.fractions.len() != radii.len() {
            bail!(
                "--fractions: give one fraction per radius ({} radii, {} fractions)",
                radii.len(),
                args.fractions.len()
            );
        }
        args.fractions.iter().map(|&f| Amount::Fraction(f)).collect()
    } else if default_radii {
        [0.2, 0.24, 0.56].map(Amount::Fraction).to_vec()
    } else {
        bail!(
            "--fractions or --counts: give one value per radius (--radii has {})",
            radii.len()
        );
    };
    for (flag, v) in [("--widths", &args.widths), ("--heights", &args.heights)] {
        if !v.is_empty() && v.len() != 3 {
            bail!("{flag}: give three coefficients C1,C2,C3, not {}", v.len());
        }
    }
    let layers = radii
        .iter()
        .zip(amounts)
        .map(|(&radius, amount)| {
            let rank = radii.iter().filter(|&&other| other > radius).count();
            let mut shape = preset_shape(args.preset, rank);
            if let [a, b, c] = args.widths[..] {
                shape.widths = [a, b, c];
            }
            if let [a, b, c] = args.heights[..] {
                shape.heights = [a, b, c];
            }
            Layer { radius, amount, shape }
        })
        .collect();
    let recipe = Recipe {
        width: args.size.0,
        height: args.size.1,
        layers,
        seed: args.seed,
        sampler: match args.sampler {
            SamplerArg::Saturate => Sampler::Saturate,
            SamplerArg::Darts => Sampler::Darts { fill: args.fill },
        },
    };
    recipe.check().map_err(|e| anyhow::anyhow!(flag_message(&e, args)))?;
    Ok(recipe)
}

/// The recipe's error in the words of the flags.
fn flag_message(e: &RecipeError, args: &Args) -> String {
    let fraction_flag = if args.counts.is_empty() {
        "--fractions"
    } else {
        "--counts"
    };
    match e {
        RecipeError::FieldSize { width, height } => format!(
            "--size: {width}x{height} cells; give at least 1x1 and at most {} cells",
            penmodel_terrain::rocks::MAX_PIXELS
        ),
        RecipeError::NoLayers => "--radii: give at least one radius".into(),
        RecipeError::RadiusNotPositive { layer, radius } => {
            format!("--radii: the {} radius, {radius}, must be above 0", ordinal(*layer))
        }
        RecipeError::RadiusTooLarge {
            layer,
            radius,
            width,
            height,
        } => {
            format!(
                "--radii: the {} radius, {radius}, is larger than the {width}x{height} field (--size)",
                ordinal(*layer)
            )
        }
        RecipeError::FractionRange { layer, fraction } => {
            format!(
                "{fraction_flag}: the {} fraction, {fraction}, must be from 0 to 1",
                ordinal(*layer)
            )
        }
        RecipeError::FractionsOverOne { sum } => {
            format!("--fractions: they add up to {sum}, more than the whole field (1)")
        }
        RecipeError::ShapeRange {
            what, value, min, max, ..
        } => {
            let flag = if what.starts_with("c_w") {
                "--widths"
            } else {
                "--heights"
            };
            format!("{flag}: {what} = {value} must be from {min} to {max}")
        }
        RecipeError::Fill(f) => format!("--fill: {f} must be above 0 and at most 10"),
    }
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let recipe = recipe(args)?;
    let s = scatter(&recipe, None).map_err(|e| anyhow::anyhow!(flag_message(&e, args)))?;
    if let Some(path) = &args.json {
        crate::out::write_with(path, |w| json::write(&recipe, &s, w).map_err(std::io::Error::from))?;
    }
    if args.obj.is_some() || args.glb.is_some() {
        // On flat ground, one unit per cell.
        let rocks = place::mesh(
            &s,
            Placement {
                origin: [0.0, 0.0],
                cell_size: 1.0,
            },
            |_, _| 0.0,
        );
        if let Some(path) = &args.obj {
            let mut bytes = Vec::new();
            bytes.extend_from_slice(
                format!(
                    "# penmodel rocks: {} x {} cells, seed {}; X = x, Y = height, Z = y (cells)\n",
                    s.width, s.height, recipe.seed
                )
                .as_bytes(),
            );
            export::write_meshes(std::iter::once(("rocks", &rocks)), &mut bytes)
                .with_context(|| format!("cannot export {}", path.display()))?;
            write(path, &bytes)?;
        }
        if let Some(path) = &args.glb {
            let mut bytes = Vec::new();
            export::write_glb_meshes(&[("rocks", &rocks)], &mut bytes)
                .with_context(|| format!("cannot export {}", path.display()))?;
            write(path, &bytes)?;
        }
    }
    if let Some(path) = &args.png {
        let scale = args.png_scale.unwrap_or_else(|| (1024 / s.width.max(s.height)).max(1));
        let mut bytes = Vec::new();
        top_view::write_top_view_png(&s, scale, &mut bytes)
            .with_context(|| format!("cannot export {}", path.display()))?;
        write(path, &bytes)?;
    }
    let per: Vec<String> = s
        .diagrams
        .iter()
        .enumerate()
        .map(|(i, d)| {
            format!(
                "r {}: {} rocks, {:.1} %",
                d.radius,
                d.cells.len(),
                100.0 * s.fraction(i)
            )
        })
        .collect();
    let t = s.timing;
    let line = format!(
        "{} × {} cells: {} rocks ({}) in {:.1} ms (seeds and diagrams {:.1}, selection {:.1}, polygons {:.1}, meshes {:.1})",
        s.width,
        s.height,
        s.rocks.len(),
        per.join("; "),
        t.total,
        t.seeds_and_diagrams,
        t.selection,
        t.polygons,
        t.meshes
    );
    // With the JSON on stdout the summary goes to stderr, so stdout stays one document.
    if args.json.as_deref() == Some(Path::new("-")) {
        eprintln!("{line}");
    } else {
        pen_host::outln!("{line}");
    }
    let short: Vec<String> = s
        .diagrams
        .iter()
        .enumerate()
        .filter(|(_, d)| !d.reached)
        .map(|(i, _)| {
            let asked = match recipe.layers.get(i).map(|l| l.amount) {
                Some(Amount::Fraction(f)) => format!("{:.1} % asked", 100.0 * f),
                Some(Amount::Count(n)) => format!("{n} rocks asked"),
                None => "its amount".to_string(),
            };
            format!("{} of the field ({asked}): its cells ran out", per[i])
        })
        .collect();
    if !short.is_empty() {
        let what = format!(
            "{}; give less, a smaller radius, or more room (the larger diagrams take theirs first)",
            short.join("; ")
        );
        if args.strict {
            bail!("--strict: {what}");
        }
        eprintln!("warning: {what}");
    }
    Ok(())
}
