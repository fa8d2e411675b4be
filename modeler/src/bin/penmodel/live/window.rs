//! A session in a window: keys, the pen's edits, frames at the display's pace, the help and the
//! notices.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use anyhow::Result;
use penmodel::feed::Feed;
use penmodel::keys::{self, KeyAction};
use penmodel::mouse::{MousePen, PointerState};
use penmodel::painter::{Overview, Painter};
use penmodel::picture::Look;
use penmodel::session::Session;
use penmodel_render::output::{Viewer, ViewerEvent};
use penmodel_render::{Place, panel};

use super::{Written, say};

/// A message shown under the mode line for a while: what a key did (saved, undone, nothing to
/// delete), what the pen's edits said — the window's user may not see the terminal.
struct Notice {
    text: String,
    since: Instant,
}

impl Notice {
    const SHOWN: Duration = Duration::from_secs(4);

    fn lines(notice: &Option<Notice>) -> Vec<String> {
        match notice {
            Some(n) if n.since.elapsed() < Notice::SHOWN => vec![n.text.clone()],
            _ => Vec::new(),
        }
    }
}

/// Says `messages` on stderr and keeps the last for the window.
fn tell(messages: Vec<String>, notice: &mut Option<Notice>) {
    if let Some(last) = messages.last() {
        *notice = Some(Notice {
            text: last.clone(),
            since: Instant::now(),
        });
    }
    say(messages, None);
}

/// Feeds `feed` to the session and says what it said; a status the mode line shows already
/// (before the first event) goes only to stderr, so the window shows it once.
fn tell_feed(session: &mut Session, feed: Feed, notice: &mut Option<Notice>) {
    let status = matches!(feed, Feed::Status(_));
    let said = session.feed(feed);
    if status && session.events() == 0 {
        say(said, None);
    } else {
        tell(said, notice);
    }
}

/// How the window takes input and starts.
pub struct Options {
    /// The pointer is the pen.
    pub mouse: Option<MousePen>,
    /// The window was opened full screen.
    pub fullscreen: bool,
}

/// Host time, µs since the Unix epoch, as a pen's events carry it.
fn now_us() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

/// Runs the session until the window closes (or a signal stops it); with `mouse`, the window's
/// pointer is the pen.
pub fn run(
    mut viewer: Viewer,
    rx: &Receiver<Feed>,
    session: &mut Session,
    look: &Look,
    painter: &mut Painter,
    stop: &AtomicBool,
    options: Options,
) -> Result<Written> {
    let Options { mut mouse, fullscreen } = options;
    // Messages show under the status line (the notice), so not on it as well.
    session.interaction.set_messages_on_status(false);
    let mut notice: Option<Notice> = None;
    if let Some(m) = &mouse {
        // What each button does, as the settings file maps them, for the first seconds.
        tell(vec![format!("mouse: {}", m.map().summary())], &mut notice);
    }
    let mouse_help = mouse.as_ref().map(|m| m.map().help()).unwrap_or_default();
    let mouse_help: Vec<(&str, &str)> = mouse_help.iter().map(|(k, d)| (k.as_str(), d.as_str())).collect();
    const FRAME: Duration = Duration::from_millis(16);
    let mut dirty = true;
    let mut last = Instant::now() - FRAME;
    let mut frames = 0;
    let mut help = false;
    let mut fullscreen = fullscreen;
    'session: while viewer.is_open() && !stop.load(Ordering::Relaxed) {
        while let Some(e) = viewer.poll() {
            let k = match &e {
                ViewerEvent::Key(k) => k,
                ViewerEvent::Closed => break 'session,
                ViewerEvent::Pointer(p) => {
                    if let Some(m) = mouse.as_mut() {
                        let frame = painter.view_frame();
                        let pointer = PointerState {
                            at: p.at,
                            buttons: p.buttons,
                            wheel: p.wheel,
                        };
                        let display = session.interaction.view().display_mm;
                        for event in m.update(pointer, display, [frame.width(), frame.height()], now_us()) {
                            tell(session.feed(Feed::Event(event)), &mut notice);
                        }
                        dirty = true;
                    }
                    continue;
                }
                ViewerEvent::Resized { .. } => {
                    dirty = true;
                    continue;
                }
            };
            match keys::action(k, session.interaction.view().display_mm) {
                Some(KeyAction::Quit) => break 'session,
                Some(KeyAction::Help) => help = !help,
                Some(KeyAction::Overview) => {
                    let next = if painter.overview() == Overview::Off {
                        Overview::Corner
                    } else {
                        Overview::Off
                    };
                    painter.set_overview(next)?;
                }
                Some(KeyAction::Fullscreen) => {
                    fullscreen = !fullscreen;
                    viewer.set_fullscreen(fullscreen)?;
                }
                Some(KeyAction::Save) => {
                    let said = match session.editor.save() {
                        Ok(()) => match session.editor.path() {
                            Some(p) => format!("saved {}", p.display()),
                            None => "saved".to_string(),
                        },
                        Err(e) => format!("cannot save: {e}"),
                    };
                    tell(vec![said], &mut notice);
                }
                Some(KeyAction::Command(c)) => {
                    session.interaction.command(&mut session.editor, c);
                    tell(session.interaction.take_messages(), &mut notice);
                }
                None => tell(vec![format!("key {k} does nothing: h shows the keys")], &mut notice),
            }
            dirty = true;
        }
        // Take what the pen sent until it is time for the next frame.
        let wait = FRAME.saturating_sub(last.elapsed());
        match rx.recv_timeout(wait.max(Duration::from_millis(1))) {
            Ok(feed) => {
                tell_feed(session, feed, &mut notice);
                dirty = true;
                while let Ok(more) = rx.try_recv() {
                    tell_feed(session, more, &mut notice);
                    if last.elapsed() >= FRAME {
                        break;
                    }
                }
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                // The pen has ended; the window stays until it is closed.
                std::thread::sleep(FRAME);
            }
        }
        // A notice going away is a change too.
        let noticed = notice
            .as_ref()
            .is_some_and(|n| n.since.elapsed() < Notice::SHOWN + FRAME * 2);
        if (dirty || noticed) && last.elapsed() >= FRAME {
            let mut frame = if session.realtime() {
                // Latched to the head's newest pose (issue 16); the feed's end shows next round.
                let said = &mut |m| tell(m, &mut notice);
                painter.session_latched(rx, session, look, true, said)?.0.clone()
            } else {
                if let Some(t) = session.last_event_us() {
                    session.interaction.advance(t);
                }
                session.frame_started();
                painter.session(session, look)?.clone()
            };
            let (w, h) = (
                painter.view_frame().width() as i32,
                painter.view_frame().height() as i32,
            );
            let viewport = penmodel_render::Bounds {
                x0: 0,
                x1: w,
                y0: 0,
                y1: h,
            };
            let style = &look.style;
            panel(
                &mut frame,
                &viewport,
                &Notice::lines(&notice),
                Place::UnderModeLine,
                style,
            );
            // The tool buttons' names, on the display where the buttons are, whatever the zoom.
            let display = session.interaction.view().display_mm;
            for (name, b, on) in session.interaction.buttons() {
                let centre = [b.corner_mm[0] + 0.5 * b.side_mm, b.corner_mm[1] + 0.5 * b.side_mm];
                let x = (centre[0] / display[0] * f64::from(w)).round() as i64;
                let y = ((1.0 - centre[1] / display[1]) * f64::from(h)).round() as i64;
                let label = if on { format!("[{name}]") } else { name.to_string() };
                panel(&mut frame, &viewport, &[label], Place::CentredOn { x, y }, style);
            }
            if help {
                panel(
                    &mut frame,
                    &viewport,
                    &keys::help_lines_with(&session.interaction.help_by_tool(), &mouse_help),
                    Place::Centre,
                    style,
                );
            }
            if viewer.show(frame).is_err() {
                break;
            }
            session.frame_produced();
            frames += 1;
            last = Instant::now();
            dirty = session.interaction.pulling() || session.interaction.view().tilt > 1e-3;
        }
    }
    Ok(Written {
        frames,
        animation: None,
        held: 0,
        shown: true,
    })
}
