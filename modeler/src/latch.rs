//! Late latching for the tracked head (issue 16): a frame due takes the feed's newest head pose
//! before its view is finished.

use std::sync::mpsc::{Receiver, RecvTimeoutError, TryRecvError};
use std::time::{Duration, Instant};

use crate::feed::Feed;
use crate::session::Session;

/// How long a due frame waits for the head's next pose, device µs: a little over the head's
/// period (60 poses/s and more), so glasses that stop reporting hold no frame up for long.
pub const HEAD_WAIT_US: u64 = 25_000;

/// The longest a frame takes events before it is drawn anyway.
pub const LATCH_MAX: Duration = Duration::from_millis(100);

/// Late latching for the tracked head (issue 16): a due frame takes everything the feed holds,
/// and while the glasses report, waits for their next pose, so its view starts right after a
/// pose arrived and shows the newest one, not the one that happened to be in when the frame
/// fell due (up to a head period older), nor one queued behind events that arrived while the
/// last frame was drawn. Only for a real-time feed ([`Session::realtime`]): an unpaced
/// simulation would be run to its end. `said` takes what the feed said; `wait` bounds the wall
/// time it waits for the next pose (a head period, [`HEAD_WAIT_US`]; the test gives a longer
/// one, so a loaded machine's scheduling cannot fail it). Returns whether the feed ended.
pub fn latch_head(
    rx: &Receiver<Feed>,
    session: &mut Session,
    said: &mut dyn FnMut(Vec<String>),
    wait: Duration,
) -> bool {
    // Whether the last thing taken was a new pose: the newest, once the feed holds no more.
    let mut fresh = false;
    let started = Instant::now();
    loop {
        let feed = match rx.try_recv() {
            Ok(f) => f,
            Err(TryRecvError::Disconnected) => return true,
            // The glasses are reporting while their last pose is recent beside the last event.
            Err(TryRecvError::Empty) if fresh || !session.head_tracked_within(HEAD_WAIT_US) => {
                return false;
            }
            // Real time: a head period of the wall clock bounds the wait (at --speed 1 exactly).
            Err(TryRecvError::Empty) => match rx.recv_timeout(wait) {
                Ok(f) => f,
                Err(RecvTimeoutError::Timeout) => return false,
                Err(RecvTimeoutError::Disconnected) => return true,
            },
        };
        let done = matches!(feed, Feed::End(_) | Feed::Failed(_));
        // A failure ends the session, which says it then.
        let failed = matches!(feed, Feed::Failed(_));
        let poses = session.head_poses();
        let messages = session.feed(feed);
        if !failed {
            said(messages);
        }
        if done {
            return true;
        }
        fresh = session.head_poses() != poses;
        // Events that take longer to handle than to come would hold the frame up for ever.
        if started.elapsed() > LATCH_MAX {
            return false;
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::interaction::Tuning;
    use crate::session::blank_document;
    use penmodel_terrain::editor::Editor;

    #[test]
    fn a_latched_frame_takes_the_newest_pose_and_the_next_one() {
        // Metres right of the 600 mm display's centre, as the camera takes the head.
        let x = |session: &Session| session.head_m().map(|h| h[0]);
        let editor = Editor::new(blank_document()).expect("a valid document");
        let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
        session.feed(head_at(Some(100.0), 0));
        let (tx, rx) = std::sync::mpsc::channel();
        // Queued while the last frame was drawn: two newer poses, then a report without a fix.
        for f in [
            head_at(Some(110.0), 16_000),
            head_at(Some(120.0), 32_000),
            head_at(None, 40_000),
        ] {
            tx.send(f).expect("queued");
        }
        // The next pose comes once the queue is taken: the frame waits for it (up to `WAIT` of
        // the wall clock here, far more than the sender's 5 ms, so a busy machine cannot fail it).
        const WAIT: Duration = Duration::from_secs(1);
        let later = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(5));
            tx.send(head_at(Some(130.0), 48_000)).expect("sent");
            tx
        });
        let mut said = Vec::new();
        assert!(!latch_head(&rx, &mut session, &mut |m| said.extend(m), WAIT));
        assert_eq!(x(&session), Some((130.0 - 300.0) * 1e-3));
        assert_eq!(session.events(), 5, "everything queued was taken");
        // Glasses that stop reporting hold a frame up no longer than a head period.
        let tx = later.join().expect("sender");
        tx.send(head_at(None, 60_000)).expect("queued");
        assert!(!latch_head(&rx, &mut session, &mut |m| said.extend(m), WAIT));
        assert_eq!((x(&session), session.events()), (Some((130.0 - 300.0) * 1e-3), 6));
        // A feed that ended: said so at once.
        drop(tx);
        assert!(latch_head(&rx, &mut session, &mut |m| said.extend(m), WAIT));
    }

    /// A head report at `device_us`: a pose `u_mm` along the display, or none (no fix).
    pub(crate) fn head_at(u_mm: Option<f64>, device_us: u64) -> Feed {
        use pen_host::events::{DisplayPoint, EventKind, HeadPose, HeadStatus, PenEvent};
        Feed::Event(PenEvent {
            kind: EventKind::Head(HeadPose {
                at: u_mm.map(|u_mm| DisplayPoint {
                    u_mm,
                    v_mm: 170.0,
                    h_mm: 650.0,
                    u_px: 0.0,
                    v_px: 0.0,
                }),
                status: if u_mm.is_some() {
                    HeadStatus::Tracked
                } else {
                    HeadStatus::Held
                },
                prediction_ms: 20,
                refused: 0,
                reason: None,
            }),
            t_us: device_us,
            point: None,
            sw: None,
            seq: Some((0, device_us)),
        })
    }
}
