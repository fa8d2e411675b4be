//! A session written to files: its frames as they fall due on the pen's clock, into the
//! animation.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Duration;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use penmodel::feed::Feed;
use penmodel::painter::Painter;
use penmodel::picture::Look;
use penmodel::session::Session;
use penmodel_render::output::Sequence;

use super::{LiveArgs, Written, say};

/// Runs the session until the feed ends (or a signal stops it), writing frames at `--fps`.
#[allow(clippy::too_many_arguments)]
pub fn run(
    args: &LiveArgs,
    rx: &Receiver<Feed>,
    session: &mut Session,
    look: &Look,
    painter: &mut Painter,
    stop: &AtomicBool,
    demo_us: Option<u64>,
) -> Result<Written> {
    // No frames at all with --fps 0: the results alone.
    let mut frames = match args.fps {
        0 => None,
        fps => Some(Sequence::create(&args.out().join("frames"), fps)?.moving_every(args.moving_every.into())),
    };
    let step_us = 1_000_000 / u64::from(args.fps.max(1));
    let mut next_us: Option<u64> = None;
    let progress = match demo_us {
        Some(total) => {
            let p = ProgressBar::new(total / 1000);
            p.set_style(
                ProgressStyle::with_template("{spinner} demo {bar:30} {pos}/{len} ms of the session, {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            p
        }
        None => ProgressBar::new_spinner(),
    };
    while !stop.load(Ordering::Relaxed) {
        let feed = match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(f) => f,
            Err(RecvTimeoutError::Timeout) => continue,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        let mut done = matches!(feed, Feed::End(_) | Feed::Failed(_));
        // A failure ends the session, which says it then.
        let failed = matches!(feed, Feed::Failed(_));
        let messages = session.feed(feed);
        if !failed {
            say(messages, Some(&progress));
        }
        if let Some(t) = session.last_event_us() {
            progress.set_position(t / 1000);
            // A reattached device restarts its clock: so do the frames.
            if next_us.is_some_and(|due| t + step_us < due) {
                next_us = None;
            }
            let due = *next_us.get_or_insert(t);
            if let Some(frames) = frames.as_mut().filter(|_| t >= due) {
                // Its head pose's age on the device's clock, drawn and produced (issue 16). In
                // real time the frame is latched to the head's newest pose; an unpaced
                // simulation's frames show the session exactly at their tick.
                let frame = if session.realtime() && !done {
                    let (frame, ended) =
                        painter.session_latched(rx, session, look, false, &mut |m| say(m, Some(&progress)))?;
                    done |= ended;
                    frame
                } else {
                    session.frame_started();
                    painter.session(session, look)?
                };
                session.frame_produced();
                frames.push(frame)?;
                painter.check_reprojection(session, look)?;
                next_us = Some(due + step_us);
                progress.set_message(format!("{} frames", frames.frames().len()));
            }
        }
        if done {
            break;
        }
    }
    progress.finish_and_clear();
    let (count, animation, held) = match frames {
        None => (0, None, 0),
        Some(frames) => {
            let paths = frames.frames().to_vec();
            let animation = frames.finish_animation()?;
            if !args.frames {
                // The animation holds them all; the single frames only on request.
                for f in &paths {
                    std::fs::remove_file(f).with_context(|| format!("cannot remove {}", f.display()))?;
                }
            }
            let held = animation.as_ref().map_or(0, |a| a.held.len());
            (paths.len(), animation.map(|a| a.path), held)
        }
    };
    Ok(Written {
        frames: count,
        animation,
        held,
        shown: false,
    })
}
