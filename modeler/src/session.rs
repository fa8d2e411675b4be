//! A modeling session: a document being edited by the pen, fed from a [`feed`](crate::feed).

use pen_host::events::PenEvent;

use crate::feed::{Calibrating, Feed};
use crate::interaction::{Interaction, Tuning, View};
use penmodel_terrain::document::{Document, Grid};
use penmodel_terrain::editor::Editor;

/// A new session's document: a 6 × 3.4 km map of 12.5 m cells (480 × 272), which the reference
/// display (600 × 340 mm) shows at 1:10 000 — a millimetre on the display is 10 m, a cell 1.25 mm.
pub fn blank_document() -> Document {
    Document::new(Grid {
        cols: 480,
        rows: 272,
        cell_size: 12.5,
    })
}

/// How the feed stands.
#[derive(Debug, Clone, PartialEq)]
pub enum State {
    /// Events are coming.
    Running,
    /// The source ended normally, saying this.
    Ended(String),
    /// The source failed, saying why.
    Failed(String),
}

/// The editor, the pen interaction, and what the feed last said.
pub struct Session {
    /// The document and its terrain.
    pub editor: Editor,
    /// The pen's state machine and the view.
    pub interaction: Interaction,
    status: String,
    calibrating: Option<Calibrating>,
    state: State,
    events: u64,
    last_event_us: Option<u64>,
}

impl Session {
    /// A session on `editor`, shown on a display of `display_mm` fitted to the document's grid.
    pub fn new(editor: Editor, display_mm: [f64; 2], tuning: Tuning) -> Session {
        let view = View::fit(display_mm, &editor.document().grid);
        Session {
            editor,
            interaction: Interaction::new(view, tuning),
            status: String::new(),
            calibrating: None,
            state: State::Running,
            events: 0,
            last_event_us: None,
        }
    }

    /// Sets the terrain's vertical scale (exaggeration) before the session starts: heights are
    /// drawn and pulled `scale` times their metres (the pulled figure stays at the pen's tip).
    pub fn set_vertical_scale(&mut self, scale: f64) {
        let tuning = *self.interaction.tuning();
        let view = View {
            exaggeration: scale,
            ..*self.interaction.view()
        };
        self.interaction = Interaction::new(view, tuning);
    }

    /// Takes one message from the feed; returns what the interaction said about it.
    pub fn feed(&mut self, feed: Feed) -> Vec<String> {
        match feed {
            Feed::Calibrating(c) => {
                self.calibrating = Some(c);
                Vec::new()
            }
            Feed::Display(mm) => {
                // Sent once the calibration is fitted: the procedure is over.
                self.calibrating = None;
                if mm != self.interaction.view().display_mm {
                    let tuning = *self.interaction.tuning();
                    let view = View {
                        // The vertical scale is the user's, whatever the display.
                        exaggeration: self.interaction.view().exaggeration,
                        ..View::fit(mm, &self.editor.document().grid)
                    };
                    self.interaction = Interaction::new(view, tuning);
                }
                Vec::new()
            }
            Feed::Status(s) => {
                self.status = s.clone();
                vec![s]
            }
            Feed::Event(e) => {
                self.calibrating = None;
                self.event(&e);
                self.interaction.take_messages()
            }
            Feed::End(s) => {
                self.state = State::Ended(s.clone());
                vec![s]
            }
            Feed::Failed(s) => {
                self.state = State::Failed(s.clone());
                vec![s]
            }
        }
    }

    /// Handles one pen event.
    pub fn event(&mut self, e: &PenEvent) {
        self.events += 1;
        if let Some((_, device_us)) = e.seq {
            self.last_event_us = Some(device_us);
        }
        self.interaction.handle(&mut self.editor, e);
    }

    /// Whether the feed is still running.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// The feed's last status line (calibrating, connected).
    pub fn status(&self) -> &str {
        &self.status
    }

    /// The calibration procedure, while it runs.
    pub fn calibrating(&self) -> Option<&Calibrating> {
        self.calibrating.as_ref()
    }

    /// Pen events handled.
    pub fn events(&self) -> u64 {
        self.events
    }

    /// The device-clock time of the last event from a report, µs (it restarts when a device
    /// is reattached).
    pub fn last_event_us(&self) -> Option<u64> {
        self.last_event_us
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertical_scale_holds_when_the_display_is_refitted() {
        let editor = Editor::new(blank_document()).expect("a valid document");
        let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
        session.set_vertical_scale(2.5);
        assert_eq!(session.interaction.view().exaggeration, 2.5);
        // The calibration reports another display: the view is fitted to it, the scale kept.
        session.feed(Feed::Display([500.0, 300.0]));
        assert_eq!(session.interaction.view().display_mm, [500.0, 300.0]);
        assert_eq!(session.interaction.view().exaggeration, 2.5);
    }
}
