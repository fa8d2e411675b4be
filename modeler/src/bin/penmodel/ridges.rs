//! `penmodel ridges`: a document's ridgeline trees and ridgelines — the trees' automatic
//! elevations (Alg. 2.4) as text or JSON, and recursive growth (Alg. 2.5) saved as a new document.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow, bail};
use penmodel_terrain::document::Ridgeline;
use penmodel_terrain::editor::Editor;
use penmodel_terrain::ridge::grow::{self, Growth};
use penmodel_terrain::ridge::layer::{self, filter_of, tree_of};
use serde_json::json;

/// Arguments of `penmodel ridges`: --elevations, or --grow with --out.
#[derive(clap::Args)]
#[command(
    group(clap::ArgGroup::new("what").args(["elevations", "grow"]).required(true)),
    after_help = "Examples (from the repository's folder):\n  \
    penmodel ridges modeler/examples/ridges/ridgelines.json --elevations --json\n  \
    penmodel ridges modeler/examples/ridges/ridgelines.json --grow 3 --seed 7 --out grown.json"
)]
pub struct Args {
    /// The document (JSON). A pending journal beside it is replayed, read-only.
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// Print each tree node's distance to its nearest end node and its elevation.
    #[arg(long)]
    elevations: bool,
    /// With --elevations: as JSON.
    #[arg(long, requires = "elevations")]
    json: bool,
    /// Grow ridgelines from the document's ridgelines and trees for this many rounds (Alg. 2.5).
    #[arg(long, value_name = "ROUNDS", requires = "out", value_parser = clap::value_parser!(u32).range(1..=8))]
    grow: Option<u32>,
    /// The random seed of --grow.
    #[arg(long, value_name = "N", default_value_t = 1)]
    seed: u64,
    /// --grow: the first round's drop spacing in metres (default 12 cells).
    #[arg(long, value_name = "M")]
    spacing: Option<f64>,
    /// --grow: the spacing is multiplied by this after each round.
    #[arg(long, value_name = "F", default_value_t = 0.7)]
    spacing_factor: f64,
    /// --grow: the flank slope grows by this many degrees each round.
    #[arg(long, value_name = "DEG", default_value_t = 5.0)]
    slope_step: f64,
    /// --grow: the grown document (the grown lines added to its ridgelines, its slope the last round's).
    #[arg(long, value_name = "OUT.json")]
    out: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let (editor, _) = Editor::open_read_only(&args.doc)?;
    let doc = editor.document();
    let ridges = doc
        .ridges
        .as_ref()
        .ok_or_else(|| anyhow!("{} has no ridges entry (docs/ridgelines.md)", args.doc.display()))?;
    if args.elevations {
        let trees: Vec<_> = ridges
            .trees
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let tree = tree_of(t);
                let (d, z) = (tree.distances(), tree.elevations());
                (j, t, d, z)
            })
            .collect();
        if args.json {
            let out = json!({
                "trees": trees.iter().map(|(j, t, d, z)| json!({
                    "tree": j,
                    "theta": t.theta,
                    "h_end": t.h_end,
                    "nodes": t.nodes.iter().enumerate().map(|(i, p)| json!({
                        "node": i, "x": p[0], "y": p[1], "distance": d[i], "elevation": z[i],
                    })).collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
            });
            pen_host::outln!("{}", serde_json::to_string_pretty(&out)?);
        } else {
            for (j, t, d, z) in &trees {
                pen_host::outln!("ridges.trees[{j}]: theta {}°, h_end {} m", t.theta, t.h_end);
                pen_host::outln!(
                    "{:>6} {:>10} {:>10} {:>10} {:>10}",
                    "node",
                    "x",
                    "y",
                    "distance",
                    "elevation"
                );
                for (i, p) in t.nodes.iter().enumerate() {
                    pen_host::outln!("{i:>6} {:>10.3} {:>10.3} {:>10.3} {:>10.3}", p[0], p[1], d[i], z[i]);
                }
            }
        }
        return Ok(());
    }
    let (Some(rounds), Some(out)) = (args.grow, &args.out) else {
        bail!("--grow ROUNDS needs --out OUT.json");
    };
    let grid = doc.grid;
    let mut g = Growth::new(rounds, args.seed, grid.cell_size);
    if let Some(s) = args.spacing {
        g.spacing = s;
    }
    g.spacing_factor = args.spacing_factor;
    g.slope_step = args.slope_step.to_radians();
    let base: Vec<_> = layer::skeletons(ridges)
        .map_err(|e| anyhow!(e))?
        .into_iter()
        .map(|(_, s)| s)
        .collect();
    let grown = grow::grow(
        &base,
        (grid.cols, grid.rows, grid.cell_size),
        filter_of(ridges),
        ridges.slope.to_radians(),
        g,
    )
    .map_err(|e| anyhow!("--grow: {e}"))?;
    let mut doc2 = doc.clone();
    let r = doc2.ridges.get_or_insert_with(Default::default);
    let n = grown.lines.len();
    r.lines
        .extend(grown.lines.into_iter().map(|points| Ridgeline { points }));
    r.slope = grown.slope.to_degrees();
    doc2.save(out)
        .with_context(|| format!("cannot save {}", out.display()))?;
    pen_host::outln!(
        "grew {n} ridgelines in {rounds} rounds; slope now {:.1}°; saved {}",
        r_slope(&doc2),
        out.display()
    );
    Ok(())
}

fn r_slope(doc: &penmodel_terrain::Document) -> f64 {
    doc.ridges.as_ref().map_or(0.0, |r| r.slope)
}
