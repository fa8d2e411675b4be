//! The viewer window: placeholder until the window lands.
