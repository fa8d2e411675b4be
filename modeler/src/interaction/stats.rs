//! What a session did: the counts of its edits and of each tool's elements, as the summary line
//! and the JSON summary `penmodel` prints at the end.

use serde_json::{Map, Value, json};

use super::tool::Counter;

/// What was done, for the session's summary.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Stats {
    /// Figures drawn and added.
    pub figures: u32,
    /// Generation regions drawn and added.
    pub regions: u32,
    /// Grabs committed with a height change.
    pub pulls: u32,
    /// Grabs committed with a slope change.
    pub slopes: u32,
    /// Figures, regions, vertices and elements moved.
    pub moves: u32,
    /// Figures, regions and elements deleted.
    pub deletes: u32,
    /// Undos that changed the document (not those with nothing to undo, or refused).
    pub undos: u32,
    /// Redos that changed the document (not those with nothing to redo, or refused).
    pub redos: u32,
    /// Edits the document refused (each with a message).
    pub refused: u32,
    /// Pen events the source reported lost.
    pub missed: u64,
    /// The tools' elements made, by counter, in the palette's order.
    made: Vec<(Counter, u32)>,
}

/// `n noun`, the noun in the plural unless `n` is 1.
pub fn count(n: u64, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

impl Stats {
    /// Nothing done yet, the tools' `counters` at 0.
    pub fn with_counters(counters: impl IntoIterator<Item = Counter>) -> Stats {
        Stats {
            made: counters.into_iter().map(|c| (c, 0)).collect(),
            ..Stats::default()
        }
    }

    /// Counts one more of a tool's elements (`key` as its [`Counter`] names it).
    pub fn count(&mut self, key: &'static str) {
        match self.made.iter_mut().find(|(c, _)| c.key == key) {
            Some((_, n)) => *n += 1,
            None => self.made.push((Counter { key, noun: None }, 1)),
        }
    }

    /// How many of a tool's elements were made (`key` as its [`Counter`] names it).
    pub fn made(&self, key: &str) -> u32 {
        self.made.iter().find(|(c, _)| c.key == key).map_or(0, |(_, n)| *n)
    }

    /// Every tool's counts, in the palette's order.
    pub fn counts(&self) -> &[(Counter, u32)] {
        &self.made
    }

    /// The summary line's counts: `1 region, 6 figures, 7 pulls, …, 1 grove`.
    pub fn summary(&self) -> String {
        let mut parts = vec![
            count(self.regions.into(), "region"),
            count(self.figures.into(), "figure"),
            count(self.pulls.into(), "pull"),
            count(self.slopes.into(), "slope"),
            count(self.undos.into(), "undo"),
        ];
        parts.extend(
            self.made
                .iter()
                .filter_map(|(c, n)| c.noun.map(|noun| count((*n).into(), noun))),
        );
        parts.join(", ")
    }

    /// The counts as a JSON object: the edits, then each tool counter by its key.
    pub fn to_json(&self) -> Value {
        let mut map = Map::new();
        let fixed = [
            ("regions", u64::from(self.regions)),
            ("figures", self.figures.into()),
            ("pulls", self.pulls.into()),
            ("slopes", self.slopes.into()),
            ("moves", self.moves.into()),
            ("deletes", self.deletes.into()),
            ("undos", self.undos.into()),
            ("redos", self.redos.into()),
            ("refused", self.refused.into()),
            ("missed", self.missed),
        ];
        for (key, n) in fixed {
            map.insert(key.into(), json!(n));
        }
        for (c, n) in &self.made {
            map.insert(c.key.into(), json!(n));
        }
        Value::Object(map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_and_json_list_every_counter_in_order() {
        let counters = [
            Counter {
                key: "rock_fields",
                noun: Some("rock field"),
            },
            Counter {
                key: "valley_rounds",
                noun: None,
            },
        ];
        let mut s = Stats::with_counters(counters);
        s.regions = 1;
        s.count("rock_fields");
        s.count("rock_fields");
        assert_eq!(s.made("rock_fields"), 2);
        assert_eq!(s.made("valley_rounds"), 0);
        assert_eq!(
            s.summary(),
            "1 region, 0 figures, 0 pulls, 0 slopes, 0 undos, 2 rock fields"
        );
        let keys: Vec<String> = s
            .to_json()
            .as_object()
            .map(|m| m.keys().cloned().collect())
            .unwrap_or_default();
        assert_eq!(keys.last().map(String::as_str), Some("valley_rounds"));
        assert_eq!(keys.len(), 12);
        assert_eq!(s.to_json()["rock_fields"], 2);
    }
}
