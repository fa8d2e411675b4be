//! `penmodel river`: one river of a document through its iterations (seed 003) — the mask after
//! each iteration and the erosion/deposition preview as PNGs, per-sample and per-iteration
//! figures as JSON (docs/rivers.md), and with `--morph` the diamond step alone on the river's
//! mask for `scripts/river_peer.py`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use penmodel_terrain::Document;
use penmodel_terrain::river::{Constants, Shape, morph};
use serde_json::json;

use crate::out::write;

/// Arguments of `penmodel river`.
#[derive(clap::Args)]
#[command(after_help = "Examples (from the repository's folder):\n  \
    penmodel river modeler/examples/rivers/omega.json --masks river-out --json river.json\n  \
    penmodel river modeler/examples/rivers/omega.json --iterations 3 --json -\n  \
    penmodel river modeler/examples/rivers/omega.json --masks out --morph 4 --json -   # the diamond step alone, for the peer")]
pub struct Args {
    /// The document (JSON).
    #[arg(value_name = "DOC.json")]
    doc: PathBuf,
    /// Which river: the index in the document's `rivers`.
    #[arg(long, default_value_t = 0)]
    index: usize,
    /// Iterations to run instead of the river's own (at most 20).
    #[arg(long)]
    iterations: Option<u32>,
    /// Folder for mask-K.png (after iteration K; 0 as drawn) and preview.png (the next iteration's
    /// erosion red, deposition light blue), over the river's window.
    #[arg(long, value_name = "DIR")]
    masks: Option<PathBuf>,
    /// Per-sample and per-iteration figures as JSON ("-" for stdout).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Also time the dilation and erosion of the final mask by the diamond of this level (1 to 6),
    /// best of 5, and with --masks write morph-mask.png, morph-dilate.png, morph-erode.png.
    #[arg(long, value_name = "LEVEL", value_parser = clap::value_parser!(u8).range(1..=6))]
    morph: Option<u8>,
}

/// An 8-bit PNG of `channels` (1 gray, 3 RGB) per pixel.
fn write_png(path: &Path, width: usize, height: usize, channels: usize, data: &[u8]) -> Result<()> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, width as u32, height as u32);
        enc.set_color(if channels == 3 {
            png::ColorType::Rgb
        } else {
            png::ColorType::Grayscale
        });
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc
            .write_header()
            .with_context(|| format!("cannot encode {}", path.display()))?;
        w.write_image_data(data)
            .with_context(|| format!("cannot encode {}", path.display()))?;
    }
    write(path, &bytes)
}

/// River cells 255, lake cells 128, land 0.
fn mask_png(dir: &Path, k: usize, shape: &Shape) -> Result<()> {
    let data: Vec<u8> = shape
        .mask
        .iter()
        .zip(&shape.lakes)
        .map(|(&m, &l)| {
            if m != 0 {
                255
            } else if l != 0 {
                128
            } else {
                0
            }
        })
        .collect();
    write_png(
        &dir.join(format!("mask-{k}.png")),
        shape.window.width,
        shape.window.height,
        1,
        &data,
    )
}

/// The best of `runs` timings of `f`, in milliseconds, and its last result.
fn best<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut out = f();
    let mut ms = f64::INFINITY;
    for _ in 0..runs {
        let t = Instant::now();
        out = f();
        ms = ms.min(t.elapsed().as_secs_f64() * 1e3);
    }
    (ms, out)
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let doc = Document::load(&args.doc)?;
    let Some(river) = doc.rivers.get(args.index) else {
        bail!(
            "--index {}: {} has {} rivers",
            args.index,
            args.doc.display(),
            doc.rivers.len()
        );
    };
    let mut river = river.clone();
    if let Some(n) = args.iterations {
        if n > penmodel_terrain::river::MAX_ITERATIONS {
            bail!("--iterations {n}: at most {}", penmodel_terrain::river::MAX_ITERATIONS);
        }
        river.iterations = n;
    }
    if let Some(dir) = &args.masks {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let t = Instant::now();
    let mut shape = Shape::new(&river, &doc.grid, &Constants::default());
    let drawn_ms = t.elapsed().as_secs_f64() * 1e3;
    let samples = shape.samples();
    if let Some(dir) = &args.masks {
        mask_png(dir, 0, &shape)?;
    }
    let mut step_ms = Vec::new();
    for k in 1..=river.iterations as usize {
        let t = Instant::now();
        shape.step();
        step_ms.push(t.elapsed().as_secs_f64() * 1e3);
        if let Some(dir) = &args.masks {
            mask_png(dir, k, &shape)?;
        }
    }
    let (w, h) = (shape.window.width, shape.window.height);
    let preview = shape.preview();
    if let Some(dir) = &args.masks {
        let mut rgb = Vec::with_capacity(3 * w * h);
        for i in 0..w * h {
            rgb.extend_from_slice(if preview.erosion[i] != 0 {
                &[220, 40, 30]
            } else if preview.deposition[i] != 0 {
                &[150, 205, 250]
            } else if shape.mask[i] != 0 {
                &[30, 70, 160]
            } else if shape.lakes[i] != 0 {
                &[60, 110, 190]
            } else {
                &[245, 242, 235]
            });
        }
        write_png(&dir.join("preview.png"), w, h, 3, &rgb)?;
    }
    let morph_json = match args.morph {
        None => serde_json::Value::Null,
        Some(level) => {
            let (dilate_ms, dilated) = best(5, || morph::dilate(&shape.mask, w, h, level));
            let (erode_ms, eroded) = best(5, || morph::erode(&shape.mask, w, h, level));
            if let Some(dir) = &args.masks {
                let scale = |m: &[u8]| m.iter().map(|&v| v * 255).collect::<Vec<u8>>();
                write_png(&dir.join("morph-mask.png"), w, h, 1, &scale(&shape.mask))?;
                write_png(&dir.join("morph-dilate.png"), w, h, 1, &scale(&dilated))?;
                write_png(&dir.join("morph-erode.png"), w, h, 1, &scale(&eroded))?;
            }
            json!({"level": level, "width": w, "height": h, "dilate_ms": dilate_ms, "erode_ms": erode_ms})
        }
    };
    if let Some(path) = &args.json {
        let doc_json = json!({
            "river": args.index,
            "window": {"c0": shape.window.c0, "r0": shape.window.r0, "width": w, "height": h},
            "drawn_ms": drawn_ms,
            "samples": samples.iter().map(|s| json!({
                "at": s.at,
                "curvature": s.curvature,
                "side": match s.turn { 1 => "left", -1 => "right", _ => "straight" },
                "outer_bank": match s.turn { 1 => "right", -1 => "left", _ => "none" },
                "level": s.level,
            })).collect::<Vec<_>>(),
            "iterations": shape.history.iter().zip(&step_ms).map(|(it, ms)| json!({
                "area": it.area,
                "eroded": it.eroded,
                "deposited": it.deposited,
                "oxbows": {"count": it.oxbows.len(), "areas": it.oxbows},
                "lakes": it.lakes,
                "lake_area": it.lake_area,
                "ms": ms,
            })).collect::<Vec<_>>(),
            "preview": {
                "erosion": preview.erosion.iter().filter(|&&v| v != 0).count(),
                "deposition": preview.deposition.iter().filter(|&&v| v != 0).count(),
            },
            "morph": morph_json,
        });
        let text = serde_json::to_string_pretty(&doc_json)? + "\n";
        if path == Path::new("-") {
            print!("{text}");
        } else {
            write(path, text.as_bytes())?;
        }
    }
    let last = shape.history.last();
    let line = format!(
        "rivers[{}]: {} samples, {} × {} window, {} iterations: {} river cells; lakes: {} ({} cells)",
        args.index,
        samples.len(),
        w,
        h,
        shape.history.len(),
        shape.mask.iter().filter(|&&m| m != 0).count(),
        last.map_or(0, |l| l.lakes),
        last.map_or(0, |l| l.lake_area),
    );
    if args.json.as_deref() == Some(Path::new("-")) {
        eprintln!("{line}");
    } else {
        pen_host::outln!("{line}");
    }
    Ok(())
}
