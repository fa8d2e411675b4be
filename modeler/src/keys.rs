//! The live window's keys, and the help it shows for them (`h`, `?`, F1): one table for both, so
//! the help cannot drift from what the keys do.
//!
//! The arrow keys move the view the way map viewers do: → shows what lies east (to the right of
//! the display), ↑ what lies north (up the display); the ground itself moves the other way.

use crate::interaction::KeyCommand;

/// What a key does in the window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeyAction {
    /// Close the window and end the session (the document is saved).
    Quit,
    /// Show or hide the help panel.
    Help,
    /// Show or hide the overview in a corner.
    Overview,
    /// Save the document now.
    Save,
    /// Fill the screen with the window, or give it back its size.
    Fullscreen,
    /// An edit or a change of view.
    Command(KeyCommand),
}

/// How far one arrow key press moves the view, as a fraction of the display's width or height.
pub const PAN_FRACTION: f64 = 0.1;
/// How much one `+` magnifies.
pub const ZOOM_STEP: f64 = 1.25;

/// The keys, as the help panel lists them: key names, then what they do.
pub const KEYS: &[(&str, &str)] = &[
    ("h ? F1", "show or hide this help"),
    ("arrows", "move the view (as map viewers do)"),
    ("+ -", "zoom in, out"),
    ("f Home", "show the whole map"),
    ("u z", "undo"),
    ("r y", "redo"),
    ("Del", "delete the highlighted figure"),
    ("s", "save the document"),
    ("o", "overview in a corner"),
    ("F11", "full screen, or back"),
    ("q Esc", "save and quit"),
];

/// What key `name` does on a display of `display_mm`; `name` is the window's key text (`"u"`,
/// `"+"`) or key name (`"ArrowLeft"`, `"F1"`).
pub fn action(name: &str, display_mm: [f64; 2]) -> Option<KeyAction> {
    let (du, dv) = (PAN_FRACTION * display_mm[0], PAN_FRACTION * display_mm[1]);
    // A pan moves the ground: to look east, the ground moves west (left).
    let pan = |du_mm, dv_mm| Some(KeyAction::Command(KeyCommand::Pan { du_mm, dv_mm }));
    match name {
        "Escape" | "q" => Some(KeyAction::Quit),
        "h" | "?" | "F1" => Some(KeyAction::Help),
        "o" => Some(KeyAction::Overview),
        "s" => Some(KeyAction::Save),
        "F11" => Some(KeyAction::Fullscreen),
        "u" | "z" => Some(KeyAction::Command(KeyCommand::Undo)),
        "r" | "y" => Some(KeyAction::Command(KeyCommand::Redo)),
        "Delete" | "Backspace" => Some(KeyAction::Command(KeyCommand::Delete)),
        "ArrowLeft" => pan(du, 0.0),
        "ArrowRight" => pan(-du, 0.0),
        "ArrowUp" => pan(0.0, -dv),
        "ArrowDown" => pan(0.0, dv),
        "+" | "=" => Some(KeyAction::Command(KeyCommand::Zoom { factor: ZOOM_STEP })),
        "-" => Some(KeyAction::Command(KeyCommand::Zoom {
            factor: 1.0 / ZOOM_STEP,
        })),
        "f" | "Home" => Some(KeyAction::Command(KeyCommand::Fit)),
        _ => None,
    }
}

/// The help panel's lines: the keys, then the pen's gestures tool by tool (`tools`: a title and
/// its lines each, [`crate::interaction::Interaction::help_by_tool`]), in aligned columns.
pub fn help_lines(tools: &[(String, Vec<(&str, &str)>)]) -> Vec<String> {
    help_lines_with(tools, &[])
}

/// [`help_lines`], with `mouse` (the mouse's switches, [`crate::mouse::MouseMap::help`]) after the keys
/// when the mouse is the pen.
pub fn help_lines_with(tools: &[(String, Vec<(&str, &str)>)], mouse: &[(&str, &str)]) -> Vec<String> {
    let width = KEYS
        .iter()
        .chain(tools.iter().flat_map(|(_, lines)| lines))
        .chain(mouse)
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    let row = |(k, d): &(&str, &str)| format!("  {k:width$}  {d}");
    let mut lines = vec!["keys".to_string()];
    lines.extend(KEYS.iter().map(row));
    if !mouse.is_empty() {
        lines.push(String::new());
        lines.push("mouse (the pen)".to_string());
        lines.extend(mouse.iter().map(row));
    }
    for (title, gestures) in tools {
        lines.push(String::new());
        lines.push(format!("pen: {title}"));
        lines.extend(gestures.iter().map(row));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interaction::{Interaction, Tuning, View};
    use crate::session::blank_document;
    use penmodel_terrain::editor::Editor;

    /// Where the ground point now at the display's centre is shown after pressing `key`.
    fn centre_after(key: &str) -> [f64; 2] {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut editor = Editor::create(&dir.path().join("doc.json"), blank_document()).expect("editor");
        let display = [600.0, 340.0];
        let view = View::fit(display, &editor.document().grid);
        let mut ui = Interaction::new(view, Tuning::default());
        let centre = ui.view().centre;
        let Some(KeyAction::Command(c)) = action(key, display) else {
            panic!("{key} is not a view command");
        };
        ui.command(&mut editor, c);
        ui.view().to_display(centre)
    }

    #[test]
    fn arrows_move_the_view_as_map_viewers_do() {
        // Looking east (→) takes what was at the centre to the left, and so on.
        let [u, v] = centre_after("ArrowRight");
        assert!(u < 300.0 - 1.0 && (v - 170.0).abs() < 1e-9, "→: {u}, {v}");
        let [u, _] = centre_after("ArrowLeft");
        assert!(u > 300.0 + 1.0, "←: {u}");
        // v grows up the display: looking north (↑) takes the centre down.
        let [u, v] = centre_after("ArrowUp");
        assert!(v < 170.0 - 1.0 && (u - 300.0).abs() < 1e-9, "↑: {u}, {v}");
        let [_, v] = centre_after("ArrowDown");
        assert!(v > 170.0 + 1.0, "↓: {v}");
    }

    #[test]
    fn the_help_names_every_key_that_acts() {
        let view = View::fit([600.0, 340.0], &blank_document().grid);
        let tools = Interaction::new(view, Tuning::default()).help_by_tool();
        let help = help_lines(&tools).join("\n");
        for (keys, _) in KEYS {
            for key in keys.split(' ') {
                let name = match key {
                    "arrows" => "ArrowLeft",
                    "Del" => "Delete",
                    "Esc" => "Escape",
                    k => k,
                };
                assert!(
                    action(name, [600.0, 340.0]).is_some(),
                    "{key} is listed but does nothing"
                );
            }
            assert!(help.contains(keys));
        }
        for (title, gestures) in &tools {
            assert!(help.contains(&format!("pen: {title}")), "{title}");
            for (gesture, what) in gestures {
                assert!(help.contains(gesture) && help.contains(what), "{gesture}");
            }
        }
        assert_eq!(action("h", [1.0, 1.0]), Some(KeyAction::Help));
        assert_eq!(action("F1", [1.0, 1.0]), Some(KeyAction::Help));
        assert_eq!(action("?", [1.0, 1.0]), Some(KeyAction::Help));
        assert_eq!(action("x", [1.0, 1.0]), None);
    }

    /// `h` lists every tool's gestures, whichever tool is on, each from the tool's own lines.
    #[test]
    fn the_help_lists_every_tools_gestures() {
        let view = View::fit([600.0, 340.0], &blank_document().grid);
        let ui = Interaction::new(view, Tuning::default());
        let tools = ui.help_by_tool();
        let titles: Vec<&str> = tools.iter().map(|(t, _)| t.as_str()).collect();
        assert_eq!(
            titles,
            ["figures (on)", "rocks", "rivers", "ridges", "trees", "every tool"],
            "the palette's tools"
        );
        let help = help_lines(&tools).join("\n");
        for needle in [
            "grab the highlighted figure",
            "a rock field inside it",
            "a river from source to mouth",
            "a ridgeline in the air",
            "plant a grove inside it",
            "undo; with SW2 held: redo",
        ] {
            assert!(help.contains(needle), "{needle} missing from\n{help}");
        }
    }
}
