//! Frame outputs: PNG, the frame folder with its animated PNG, and the viewer without a display.

use std::fs::File;
use std::io::BufReader;

use penmodel_render::Frame;
use penmodel_render::output::{self, OutputError, Sequence};
#[cfg(feature = "window")]
use penmodel_render::output::{Viewer, WindowError};

fn frame(w: u32, h: u32, seed: u8) -> Frame {
    let mut f = Frame::new(w, h).unwrap();
    for (i, p) in f.pixels_mut().iter_mut().enumerate() {
        let v = (i as u8).wrapping_mul(31).wrapping_add(seed);
        *p = [v, v.wrapping_add(80), 255 - v, 255];
    }
    f
}

fn decode(path: &std::path::Path) -> (png::Reader<BufReader<File>>, Vec<u8>) {
    let mut reader = png::Decoder::new(BufReader::new(File::open(path).unwrap()))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (reader, buf)
}

#[test]
fn a_png_holds_the_frame_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.png");
    let f = frame(37, 21, 5);
    output::write_png(&f, &path).unwrap();
    let (reader, bytes) = decode(&path);
    assert_eq!((reader.info().width, reader.info().height), (37, 21));
    assert_eq!(reader.info().color_type, png::ColorType::Rgba);
    assert_eq!(bytes, f.as_bytes());
}

#[test]
fn a_sequence_writes_each_frame_and_an_animation_of_them_all() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let frames: Vec<Frame> = (0..4).map(|i| frame(20, 10, i * 40)).collect();
    let mut seq = Sequence::create(&out, 10).unwrap();
    for f in &frames {
        seq.push(f).unwrap();
    }
    assert_eq!(seq.frames().len(), 4);
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(decode(&out.join(format!("frame_{i:05}.png"))).1, f.as_bytes());
    }
    let anim = seq.finish().unwrap().unwrap();
    assert_eq!(anim, out.join("animation.png"));
    let reader = png::Decoder::new(BufReader::new(File::open(&anim).unwrap()))
        .read_info()
        .unwrap();
    let actl = reader.info().animation_control.unwrap();
    assert_eq!((actl.num_frames, actl.num_plays), (4, 0));
    for (shown, f) in play(&anim).iter().zip(&frames) {
        assert_eq!(shown, f.as_bytes());
    }
}

/// Plays an APNG as a viewer does (dispose NONE, blend SOURCE or OVER), from the spec's rules,
/// and returns the canvas after each frame.
fn play(path: &std::path::Path) -> Vec<Vec<u8>> {
    played(path).into_iter().map(|p| p.canvas).collect()
}

/// One frame of an APNG as played.
struct Played {
    /// The canvas after it.
    canvas: Vec<u8>,
    /// How long it shows, seconds.
    delay_s: f64,
    /// Pixels of its data that are opaque and equal to the canvas under them (stored though
    /// unchanged).
    restated: usize,
}

fn played(path: &std::path::Path) -> Vec<Played> {
    let mut decoder = png::Decoder::new(BufReader::new(File::open(path).unwrap()));
    // RGB with a tRNS key comes out as RGBA, the key's pixels with alpha 0.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().unwrap();
    let (w, frames) = (
        reader.info().width as usize,
        reader.info().animation_control.unwrap().num_frames,
    );
    let mut canvas = vec![0u8; w * reader.info().height as usize * 4];
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let mut shown = Vec::new();
    for _ in 0..frames {
        let info = reader.next_frame(&mut buf).unwrap();
        let fc = reader.info().frame_control.unwrap();
        assert_eq!(fc.dispose_op, png::DisposeOp::None);
        let (x0, y0, fw) = (fc.x_offset as usize, fc.y_offset as usize, fc.width as usize);
        let mut restated = 0;
        for (j, src) in buf[..info.buffer_size()].chunks_exact(fw * 4).enumerate() {
            for (i, px) in src.chunks_exact(4).enumerate() {
                let at = ((y0 + j) * w + x0 + i) * 4;
                restated += usize::from(px[3] == 255 && canvas[at..at + 4] == *px);
                match (fc.blend_op, px[3]) {
                    (png::BlendOp::Over, 0) => {}
                    (png::BlendOp::Over, 255) | (png::BlendOp::Source, _) => canvas[at..at + 4].copy_from_slice(px),
                    (png::BlendOp::Over, a) => panic!("OVER with a partial alpha {a}"),
                }
            }
        }
        // A zero denominator means 100 (the APNG spec).
        let den = if fc.delay_den == 0 { 100 } else { fc.delay_den };
        shown.push(Played {
            canvas: canvas.clone(),
            delay_s: f64::from(fc.delay_num) / f64::from(den),
            restated,
        });
    }
    shown
}

/// Frames that change in parts: a box that moves, a frame with no change, then one changed
/// pixel; with `translucent`, a frame with a pixel that is not opaque among them.
fn changing_frames(translucent: bool) -> Vec<Frame> {
    let (w, h) = (64u32, 40u32);
    let first = frame(w, h, 3);
    let mut frames = vec![first.clone()];
    for k in 0..3u32 {
        let mut f = frames.last().unwrap().clone();
        for y in 5 + k..12 + k {
            for x in 10 + 4 * k..30 + 4 * k {
                f.pixels_mut()[(y * w + x) as usize] = [200, 10 * k as u8, 50, 255];
            }
        }
        frames.push(f);
    }
    frames.push(frames.last().unwrap().clone());
    if translucent {
        let mut t = frames.last().unwrap().clone();
        t.pixels_mut()[5] = [1, 2, 3, 128];
        frames.push(t);
    }
    let mut one = first.clone();
    one.pixels_mut()[(h * w - 1) as usize] = [9, 9, 9, 255];
    frames.push(one);
    frames
}

#[test]
fn the_animation_stores_what_changed_and_plays_back_every_frame_exactly() {
    for (translucent, colour) in [(false, png::ColorType::Rgb), (true, png::ColorType::Rgba)] {
        let dir = tempfile::tempdir().unwrap();
        let frames = changing_frames(translucent);
        let mut seq = Sequence::create(dir.path(), 25).unwrap();
        for f in &frames {
            seq.push(f).unwrap();
        }
        let anim = seq.finish().unwrap().unwrap();
        let (reader, _) = decode(&anim);
        assert_eq!(reader.info().color_type, colour, "translucent: {translucent}");
        let shown = play(&anim);
        assert_eq!(shown.len(), frames.len());
        for (i, (s, f)) in shown.iter().zip(&frames).enumerate() {
            assert!(
                s == f.as_bytes(),
                "frame {i} plays back differently (translucent: {translucent})"
            );
        }
        // Stored as deltas: far smaller than the same frames stored whole.
        let whole: u64 = (0..frames.len())
            .map(|i| {
                std::fs::metadata(dir.path().join(format!("frame_{i:05}.png")))
                    .unwrap()
                    .len()
            })
            .sum();
        let stored = std::fs::metadata(&anim).unwrap().len();
        assert!(stored * 2 < whole, "{stored} bytes for frames of {whole} bytes");
    }
}

#[test]
fn a_sequence_refuses_a_frame_of_another_size() {
    let dir = tempfile::tempdir().unwrap();
    let mut seq = Sequence::create(dir.path(), 25).unwrap();
    seq.push(&frame(8, 8, 0)).unwrap();
    assert!(matches!(
        seq.push(&frame(9, 8, 0)),
        Err(OutputError::FrameSize {
            index: 1,
            got: (9, 8),
            expected: (8, 8)
        })
    ));
    let empty = Sequence::create(&dir.path().join("none"), 25).unwrap();
    assert_eq!(empty.finish().unwrap(), None);
}

// The window is behind the `window` feature; without it the crate has no viewer to test.
#[cfg(feature = "window")]
#[test]
fn the_viewer_says_so_without_a_display() {
    let has_display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    if !has_display {
        assert_eq!(Viewer::open("test", 64, 48).err(), Some(WindowError::NoDisplay));
    }
}

#[test]
fn difference_is_the_mean_absolute_channel_error_and_psnr() {
    let mut a = frame(4, 2, 0);
    a.pixels_mut()[5] = [40, 90, 188, 255];
    let mut b = a.clone();
    assert_eq!(a.difference(&b).map(|d| d.0), Some(0.0));
    assert!(a.difference(&b).unwrap().1.is_infinite());
    // One pixel off by 30 in red and 12 in blue; alpha does not count.
    b.pixels_mut()[5] = [10, 90, 200, 0];
    let n = 8.0 * 3.0;
    let (mad, psnr) = a.difference(&b).unwrap();
    assert!((mad - 42.0 / n).abs() < 1e-12, "{mad}");
    let mse = (900.0 + 144.0) / n;
    assert!((psnr - 10.0 * (65025.0 / mse).log10()).abs() < 1e-9, "{psnr}");
    assert_eq!(a.difference(&frame(2, 4, 0)), None);
}

#[test]
fn scattered_changes_play_back_exactly_whichever_way_a_delta_is_stored() {
    // A quarter of the pixels of a smooth frame change by one, so a delta of transparent unchanged
    // pixels between them deflates worse than the unchanged ones restated.
    let (w, h) = (96u32, 64u32);
    let mut first = Frame::new(w, h).unwrap();
    for (i, p) in first.pixels_mut().iter_mut().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        *p = [(2 * x) as u8, (3 * y) as u8, (x + y) as u8, 255];
    }
    let mut next = first.clone();
    for (i, p) in next.pixels_mut().iter_mut().enumerate() {
        // Scattered: a multiplicative hash's top two bits.
        if (i as u32).wrapping_mul(2_654_435_761) >> 30 == 0 {
            p[0] = p[0].wrapping_add(1);
        }
    }
    // And a frame with one small changed box, stored with its unchanged pixels transparent.
    let mut last = next.clone();
    last.pixels_mut()[(10 * w + 10) as usize] = [1, 2, 3, 255];
    let frames = [first, next, last];
    let dir = tempfile::tempdir().unwrap();
    let mut seq = Sequence::create(dir.path(), 25).unwrap();
    for f in &frames {
        seq.push(f).unwrap();
    }
    let anim = seq.finish().unwrap().unwrap();
    let shown = played(&anim);
    assert_eq!(shown.len(), frames.len());
    for (i, (s, f)) in shown.iter().zip(&frames).enumerate() {
        assert!(s.canvas == f.as_bytes(), "frame {i} plays back differently");
        assert!((s.delay_s - 1.0 / 25.0).abs() < 1e-9, "frame {i} shows {} s", s.delay_s);
    }
    assert!(shown[1].restated > 0, "the scattered delta restates unchanged pixels");
}

#[test]
fn moving_frames_are_thinned_and_the_rest_shown_longer_on_the_same_clock() {
    let (w, h) = (48u32, 32u32);
    let fps = 10;
    // 1..=6 and 9..=11 change everywhere (the view moving); 7 and 8 one pixel each.
    let mut frames = vec![frame(w, h, 0)];
    for k in 1..12u8 {
        let f = if (7..=8).contains(&k) {
            let mut f = frames.last().unwrap().clone();
            f.pixels_mut()[usize::from(k)] = [k, k, k, 255];
            f
        } else {
            frame(w, h, 7 * k)
        };
        frames.push(f);
    }
    let dir = tempfile::tempdir().unwrap();
    let mut seq = Sequence::create(dir.path(), fps).unwrap().moving_every(3);
    for f in &frames {
        seq.push(f).unwrap();
    }
    // The first; of each moving run every third since the last held; each still frame; the last.
    let expected = vec![0, 3, 6, 7, 8, 11];
    assert_eq!(seq.held(), expected);
    let animation = seq.finish_animation().unwrap().unwrap();
    assert_eq!(animation.held, expected);
    let shown = played(&animation.path);
    assert_eq!(shown.len(), expected.len());
    for (k, (s, &i)) in shown.iter().zip(&expected).enumerate() {
        assert!(s.canvas == frames[i].as_bytes(), "held frame {k} is not frame {i}");
        // Shown until the next one held: the frames left out pass on the same clock.
        let until = expected.get(k + 1).copied().unwrap_or(frames.len());
        let want = (until - i) as f64 / f64::from(fps);
        assert!(
            (s.delay_s - want).abs() < 1e-9,
            "frame {i} shows {} s, not {want}",
            s.delay_s
        );
    }
    let total: f64 = shown.iter().map(|s| s.delay_s).sum();
    assert!((total - frames.len() as f64 / f64::from(fps)).abs() < 1e-9);
    // Every frame is still written as its own file.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), frames.len() + 1);
}
