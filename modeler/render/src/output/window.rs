//! The viewer: a window that shows the frames pushed to it.
//!
//! [`Viewer::open`] starts the window on a thread of its own, so the caller — a live session
//! reading pen reports — keeps its loop and simply calls [`Viewer::show`] with each new frame;
//! input comes back through [`Viewer::poll`]. winit opens the window and softbuffer copies the
//! pixels into it; both load X11 or Wayland at run time, so nothing is needed at build time and a
//! machine without a display gets [`WindowError::NoDisplay`] instead of a crash. A frame smaller
//! or larger than the window is scaled to fit (nearest pixel, aspect kept, black bars).
//!
//! winit allows one event loop per process, created on any thread only on X11 and Wayland (Linux
//! and the BSDs), so there is at most one viewer per process; opening a second one fails.

use std::num::NonZeroU32;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::thread::JoinHandle;

use thiserror::Error;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop, EventLoopProxy};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Fullscreen, Window, WindowId};

use crate::Frame;

/// Why the viewer could not be opened or used.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum WindowError {
    /// Neither `DISPLAY` nor `WAYLAND_DISPLAY` is set.
    #[error("no display (neither DISPLAY nor WAYLAND_DISPLAY is set)")]
    NoDisplay,
    /// The window system refused (no server, no library, a second viewer, another platform).
    #[error("cannot open a window: {0}")]
    Platform(String),
    /// The window has been closed.
    #[error("the window is closed")]
    Closed,
}

/// What the viewer reports.
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewerEvent {
    /// The window's drawable area is now this many pixels.
    Resized { width: u32, height: u32 },
    /// A key was pressed: its text (`"u"`, `"+"`) or name (`"Escape"`, `"ArrowLeft"`).
    /// Space is not a key here: it is the pointer's third button ([`Pointer`]).
    Key(String),
    /// The mouse (or a tablet's pointer) moved, a button changed or the wheel turned.
    Pointer(Pointer),
    /// The user closed the window.
    Closed,
}

/// The pointer over the frame shown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pointer {
    /// Where, as fractions of the frame's width and height from its top-left corner; `None`
    /// when the pointer is off the frame (outside the window, or on the black bars).
    pub at: Option<[f64; 2]>,
    /// Left, right and middle button held (the middle one also while Space is held).
    pub buttons: [bool; 3],
    /// Wheel notches turned since the last event, away from the user positive.
    pub wheel: f64,
}

enum Command {
    Show(Arc<Frame>),
    Fullscreen(bool),
    Close,
}

/// A window showing frames, running on its own thread.
pub struct Viewer {
    proxy: EventLoopProxy<Command>,
    events: Receiver<ViewerEvent>,
    thread: Option<JoinHandle<()>>,
    open: bool,
}

struct App {
    title: String,
    size: (u32, u32),
    window: Option<Rc<Window>>,
    surface: Option<softbuffer::Surface<Rc<Window>, Rc<Window>>>,
    frame: Option<Arc<Frame>>,
    events: Sender<ViewerEvent>,
    failed: Option<Sender<Result<(), WindowError>>>,
    /// The cursor in window pixels, while it is in the window.
    cursor: Option<(f64, f64)>,
    /// Left, right and middle button, and Space.
    held: [bool; 4],
}

impl App {
    fn create(&mut self, el: &ActiveEventLoop) -> Result<(), WindowError> {
        let platform = |e: &dyn std::fmt::Display| WindowError::Platform(e.to_string());
        let attrs = Window::default_attributes()
            .with_title(self.title.clone())
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1));
        let window = Rc::new(el.create_window(attrs).map_err(|e| platform(&e))?);
        let context = softbuffer::Context::new(window.clone()).map_err(|e| platform(&e))?;
        let surface = softbuffer::Surface::new(&context, window.clone()).map_err(|e| platform(&e))?;
        self.window = Some(window);
        self.surface = Some(surface);
        Ok(())
    }

    fn present(&mut self) {
        let (Some(window), Some(surface)) = (&self.window, &mut self.surface) else {
            return;
        };
        let size = window.inner_size();
        let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) else {
            return;
        };
        if surface.resize(w, h).is_err() {
            return;
        }
        let Ok(mut buffer) = surface.buffer_mut() else { return };
        let (w, h) = (size.width as usize, size.height as usize);
        buffer.fill(0);
        if let Some(frame) = &self.frame {
            blit(frame, &mut buffer, w, h);
        }
        let _ = buffer.present();
    }
}

/// Where `frame` goes in a `w × h` window: its top-left corner and drawn size, pixels.
fn placement(frame: (usize, usize), w: usize, h: usize) -> (usize, usize, usize, usize) {
    let (fw, fh) = frame;
    let scale = (w as f64 / fw as f64).min(h as f64 / fh as f64);
    let (dw, dh) = (
        ((fw as f64 * scale) as usize).max(1),
        ((fh as f64 * scale) as usize).max(1),
    );
    ((w.saturating_sub(dw)) / 2, (h.saturating_sub(dh)) / 2, dw, dh)
}

/// The window pixel `(x, y)` as fractions of the frame placed by [`placement`], if on it.
fn on_frame(frame: (usize, usize), window: (usize, usize), (x, y): (f64, f64)) -> Option<[f64; 2]> {
    let (ox, oy, dw, dh) = placement(frame, window.0, window.1);
    let (fx, fy) = ((x - ox as f64) / dw as f64, (y - oy as f64) / dh as f64);
    ((0.0..=1.0).contains(&fx) && (0.0..=1.0).contains(&fy)).then_some([fx, fy])
}

/// Scales `frame` into a `w × h` 0RGB buffer, aspect kept, centred.
fn blit(frame: &Frame, out: &mut [u32], w: usize, h: usize) {
    let (fw, fh) = (frame.width() as usize, frame.height() as usize);
    let (ox, oy, dw, dh) = placement((fw, fh), w, h);
    let px = frame.pixels();
    for y in 0..dh.min(h) {
        let sy = (y * fh / dh).min(fh - 1);
        let row = &mut out[(oy + y) * w..(oy + y + 1) * w];
        for x in 0..dw.min(w) {
            let sx = (x * fw / dw).min(fw - 1);
            let p = px[sy * fw + sx];
            row[ox + x] = (u32::from(p[0]) << 16) | (u32::from(p[1]) << 8) | u32::from(p[2]);
        }
    }
}

fn key_name(key: &Key) -> Option<String> {
    match key {
        Key::Character(s) => Some(s.to_string()),
        Key::Named(NamedKey::Space) => Some(" ".into()),
        // Modifiers change other keys; alone they are not keys a user means.
        Key::Named(
            NamedKey::Shift
            | NamedKey::Control
            | NamedKey::Alt
            | NamedKey::AltGraph
            | NamedKey::Super
            | NamedKey::Meta
            | NamedKey::Hyper
            | NamedKey::CapsLock
            | NamedKey::NumLock
            | NamedKey::Fn,
        ) => None,
        Key::Named(named) => Some(format!("{named:?}")),
        _ => None,
    }
}

impl App {
    /// Tells the pointer's state, `wheel` notches turned with it.
    fn pointer(&self, wheel: f64) {
        let Some(window) = &self.window else {
            return;
        };
        // Before the first frame, the one that will come: the window's size when opened.
        let frame = self.frame.as_ref().map_or(self.size, |f| (f.width(), f.height()));
        let size = window.inner_size();
        let at = self.cursor.and_then(|c| {
            on_frame(
                (frame.0 as usize, frame.1 as usize),
                (size.width as usize, size.height as usize),
                c,
            )
        });
        let h = self.held;
        let _ = self.events.send(ViewerEvent::Pointer(Pointer {
            at,
            buttons: [h[0], h[1], h[2] || h[3]],
            wheel,
        }));
    }
}

impl ApplicationHandler<Command> for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let result = self.create(el);
        let failed = result.is_err();
        if let Some(tx) = self.failed.take() {
            let _ = tx.send(result);
        }
        if failed {
            el.exit();
        }
    }

    fn user_event(&mut self, el: &ActiveEventLoop, command: Command) {
        match command {
            Command::Show(frame) => {
                self.frame = Some(frame);
                if let Some(w) = &self.window {
                    w.request_redraw();
                }
            }
            Command::Fullscreen(on) => {
                if let Some(w) = &self.window {
                    w.set_fullscreen(on.then_some(Fullscreen::Borderless(None)));
                }
            }
            Command::Close => el.exit(),
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => {
                let _ = self.events.send(ViewerEvent::Closed);
                el.exit();
            }
            WindowEvent::Resized(size) => {
                let _ = self.events.send(ViewerEvent::Resized {
                    width: size.width,
                    height: size.height,
                });
                if let Some(w) = &self.window {
                    w.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => self.present(),
            WindowEvent::KeyboardInput { event, .. } if event.logical_key == Key::Named(NamedKey::Space) => {
                let down = event.state == ElementState::Pressed;
                if self.held[3] != down {
                    self.held[3] = down;
                    self.pointer(0.0);
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if let Some(name) = key_name(&event.logical_key) {
                    let _ = self.events.send(ViewerEvent::Key(name));
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = Some((position.x, position.y));
                self.pointer(0.0);
            }
            WindowEvent::CursorLeft { .. } => {
                self.cursor = None;
                self.pointer(0.0);
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let i = match button {
                    MouseButton::Left => 0,
                    MouseButton::Right => 1,
                    MouseButton::Middle => 2,
                    _ => return,
                };
                self.held[i] = state == ElementState::Pressed;
                self.pointer(0.0);
            }
            WindowEvent::MouseWheel { delta, .. } => {
                // A line is a notch; a touchpad's pixels count 20 to a notch.
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 20.0,
                };
                self.pointer(notches);
            }
            _ => {}
        }
    }
}

/// Whether a display (X11 or Wayland) is announced in the environment.
pub fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

#[cfg(any(
    target_os = "linux",
    target_os = "freebsd",
    target_os = "openbsd",
    target_os = "netbsd"
))]
fn event_loop() -> Result<EventLoop<Command>, WindowError> {
    use winit::platform::x11::EventLoopBuilderExtX11;
    let mut builder = EventLoop::with_user_event();
    // Sets the flag X11 and Wayland share: the loop may run off the main thread.
    builder.with_any_thread(true);
    builder.build().map_err(|e| WindowError::Platform(e.to_string()))
}

#[cfg(not(any(
    target_os = "linux",
    target_os = "freebsd",
    target_os = "openbsd",
    target_os = "netbsd"
)))]
fn event_loop() -> Result<EventLoop<Command>, WindowError> {
    Err(WindowError::Platform(
        "the viewer runs its window on its own thread, which needs X11 or Wayland".into(),
    ))
}

impl Viewer {
    /// Opens a window of `width × height` pixels titled `title`, or says why not.
    pub fn open(title: &str, width: u32, height: u32) -> Result<Viewer, WindowError> {
        if !has_display() {
            return Err(WindowError::NoDisplay);
        }
        let (ready_tx, ready_rx) = mpsc::channel();
        let (events_tx, events_rx) = mpsc::channel();
        let (title, size) = (title.to_owned(), (width.max(1), height.max(1)));
        let thread = std::thread::Builder::new()
            .name("penmodel-viewer".into())
            .spawn(move || {
                let event_loop = match event_loop() {
                    Ok(el) => el,
                    Err(e) => {
                        let _ = ready_tx.send(Err(e));
                        return;
                    }
                };
                let (created_tx, created_rx) = mpsc::channel();
                let _ = ready_tx.send(Ok((event_loop.create_proxy(), created_rx)));
                let mut app = App {
                    title,
                    size,
                    window: None,
                    surface: None,
                    frame: None,
                    events: events_tx,
                    failed: Some(created_tx),
                    cursor: None,
                    held: [false; 4],
                };
                if let Err(e) = event_loop.run_app(&mut app)
                    && let Some(tx) = app.failed.take()
                {
                    let _ = tx.send(Err(WindowError::Platform(e.to_string())));
                }
            })
            .map_err(|e| WindowError::Platform(e.to_string()))?;
        let closed = |_| WindowError::Platform("the window thread stopped".into());
        let (proxy, created) = ready_rx.recv().map_err(closed)??;
        created.recv().map_err(closed)??;
        Ok(Viewer {
            proxy,
            events: events_rx,
            thread: Some(thread),
            open: true,
        })
    }

    /// Shows `frame` (scaled to the window) until the next one.
    pub fn show(&mut self, frame: Frame) -> Result<(), WindowError> {
        if !self.open {
            return Err(WindowError::Closed);
        }
        self.proxy
            .send_event(Command::Show(Arc::new(frame)))
            .map_err(|_| WindowError::Closed)
    }

    /// Fills the screen with the window (borderless, on its monitor), or gives it back its size.
    pub fn set_fullscreen(&mut self, on: bool) -> Result<(), WindowError> {
        self.proxy
            .send_event(Command::Fullscreen(on))
            .map_err(|_| WindowError::Closed)
    }

    /// The next event, if any, without waiting.
    pub fn poll(&mut self) -> Option<ViewerEvent> {
        match self.events.try_recv() {
            Ok(ViewerEvent::Closed) => {
                self.open = false;
                Some(ViewerEvent::Closed)
            }
            Ok(e) => Some(e),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                self.open = false;
                None
            }
        }
    }

    /// Whether the window is still open.
    pub fn is_open(&self) -> bool {
        self.open
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.proxy.send_event(Command::Close);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_pixel_is_found_on_the_frame_it_shows() {
        // A 200 × 100 frame in a 400 × 400 window: drawn 400 × 200 from y = 100.
        assert_eq!(on_frame((200, 100), (400, 400), (0.0, 100.0)), Some([0.0, 0.0]));
        assert_eq!(on_frame((200, 100), (400, 400), (100.0, 250.0)), Some([0.25, 0.75]));
        assert_eq!(on_frame((200, 100), (400, 400), (100.0, 50.0)), None, "on the bar");
    }

    #[test]
    fn blit_keeps_the_aspect_and_centres() {
        let mut f = Frame::new(2, 1).unwrap();
        f.pixels_mut().copy_from_slice(&[[255, 0, 0, 255], [0, 0, 255, 255]]);
        let mut out = vec![7u32; 4 * 4];
        blit(&f, &mut out, 4, 4);
        // 2 × 1 scaled by 2 into rows 1–2; rows 0 and 3 untouched.
        assert_eq!(&out[0..4], &[7; 4]);
        assert_eq!(&out[4..8], &[0xff0000, 0xff0000, 0x0000ff, 0x0000ff]);
        assert_eq!(&out[8..12], &[0xff0000, 0xff0000, 0x0000ff, 0x0000ff]);
        assert_eq!(&out[12..16], &[7; 4]);
    }
}
