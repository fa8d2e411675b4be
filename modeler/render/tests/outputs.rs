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
    let mut reader = png::Decoder::new(BufReader::new(File::open(&anim).unwrap()))
        .read_info()
        .unwrap();
    let actl = reader.info().animation_control.unwrap();
    assert_eq!((actl.num_frames, actl.num_plays), (4, 0));
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for f in &frames {
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(&buf[..info.buffer_size()], f.as_bytes());
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
