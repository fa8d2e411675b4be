//! Addresses of figures and curves in a document, written the way validation errors name them:
//! `regions[1].figures[0].figures[2]`, `regions[1].boundary`.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::document::{Document, Figure, Point};

/// Where a figure is: its top-level region, then its index in each nested figure list.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct FigurePath {
    region: usize,
    figures: Vec<usize>,
}

impl FigurePath {
    /// Figure `figure` of top-level region `region`.
    pub fn new(region: usize, figure: usize) -> FigurePath {
        FigurePath {
            region,
            figures: vec![figure],
        }
    }

    /// Figure `figure` nested in this (closed) figure.
    pub fn child(&self, figure: usize) -> FigurePath {
        let mut p = self.clone();
        p.figures.push(figure);
        p
    }

    /// The top-level region's index.
    pub fn region(&self) -> usize {
        self.region
    }

    /// The indices from the region down to the figure (never empty).
    pub fn indices(&self) -> &[usize] {
        &self.figures
    }

    /// The figure's index in its list.
    pub fn index(&self) -> usize {
        self.figures.last().copied().unwrap_or(0)
    }

    /// The closed figure this figure is nested in, if it is not a top-level region's figure.
    pub fn parent(&self) -> Option<FigurePath> {
        (self.figures.len() > 1).then(|| FigurePath {
            region: self.region,
            figures: self.figures[..self.figures.len() - 1].to_vec(),
        })
    }

    /// The figure in `doc`.
    pub fn get<'a>(&self, doc: &'a Document) -> Option<&'a Figure> {
        let mut list = &doc.regions.get(self.region)?.figures;
        let (last, up) = self.figures.split_last()?;
        for &i in up {
            list = &list.get(i)?.figures;
        }
        list.get(*last)
    }

    /// The figure in `doc`, mutably.
    pub fn get_mut<'a>(&self, doc: &'a mut Document) -> Option<&'a mut Figure> {
        let (last, _) = self.figures.split_last()?;
        self.list_mut(doc)?.get_mut(*last)
    }

    /// The list the figure is (or would be) in.
    pub fn list_mut<'a>(&self, doc: &'a mut Document) -> Option<&'a mut Vec<Figure>> {
        let mut list = &mut doc.regions.get_mut(self.region)?.figures;
        let (_, up) = self.figures.split_last()?;
        for &i in up {
            list = &mut list.get_mut(i)?.figures;
        }
        Some(list)
    }

    /// The closed curve bounding the figure's region: the region's boundary or the enclosing figure's points.
    pub fn edge<'a>(&self, doc: &'a Document) -> Option<&'a [Point]> {
        match self.parent() {
            None => Some(&doc.regions.get(self.region)?.boundary),
            Some(p) => Some(&p.get(doc)?.points),
        }
    }
}

impl fmt::Display for FigurePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "regions[{}]", self.region)?;
        for i in &self.figures {
            write!(f, ".figures[{i}]")?;
        }
        Ok(())
    }
}

/// A path that is not of the form `regions[R].figures[F]…`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("not a figure path: {0:?} (expected e.g. regions[0].figures[1])")]
pub struct BadPath(pub String);

/// Parses `name[N]` at the start of `s`, returning N and the rest.
fn indexed<'a>(s: &'a str, name: &str) -> Option<(usize, &'a str)> {
    let s = s.strip_prefix(name)?.strip_prefix('[')?;
    let end = s.find(']')?;
    let n = s[..end].parse().ok()?;
    Some((n, &s[end + 1..]))
}

impl FromStr for FigurePath {
    type Err = BadPath;

    fn from_str(s: &str) -> Result<FigurePath, BadPath> {
        let bad = || BadPath(s.to_owned());
        let (region, mut rest) = indexed(s, "regions").ok_or_else(bad)?;
        let mut figures = Vec::new();
        while !rest.is_empty() {
            let (i, r) = indexed(rest, ".figures").ok_or_else(bad)?;
            figures.push(i);
            rest = r;
        }
        if figures.is_empty() {
            return Err(bad());
        }
        Ok(FigurePath { region, figures })
    }
}

impl TryFrom<String> for FigurePath {
    type Error = BadPath;

    fn try_from(s: String) -> Result<FigurePath, BadPath> {
        s.parse()
    }
}

impl From<FigurePath> for String {
    fn from(p: FigurePath) -> String {
        p.to_string()
    }
}

/// A curve whose points can be edited: a region's boundary or a figure.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum CurvePath {
    /// The boundary of top-level region N.
    Boundary(usize),
    /// A figure's points.
    Figure(FigurePath),
}

impl fmt::Display for CurvePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CurvePath::Boundary(r) => write!(f, "regions[{r}].boundary"),
            CurvePath::Figure(p) => p.fmt(f),
        }
    }
}

impl FromStr for CurvePath {
    type Err = BadPath;

    fn from_str(s: &str) -> Result<CurvePath, BadPath> {
        match indexed(s, "regions") {
            Some((r, ".boundary")) => Ok(CurvePath::Boundary(r)),
            _ => s.parse().map(CurvePath::Figure),
        }
    }
}

impl TryFrom<String> for CurvePath {
    type Error = BadPath;

    fn try_from(s: String) -> Result<CurvePath, BadPath> {
        s.parse()
    }
}

impl From<CurvePath> for String {
    fn from(p: CurvePath) -> String {
        p.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let p = FigurePath::new(1, 0).child(2);
        assert_eq!(p.to_string(), "regions[1].figures[0].figures[2]");
        assert_eq!("regions[1].figures[0].figures[2]".parse::<FigurePath>(), Ok(p.clone()));
        assert_eq!(p.parent(), Some(FigurePath::new(1, 0)));
        assert_eq!("regions[3].boundary".parse::<CurvePath>(), Ok(CurvePath::Boundary(3)));
        assert!("regions[1]".parse::<FigurePath>().is_err());
        assert!("regions[1].figures[x]".parse::<FigurePath>().is_err());
        assert!("regions[1].figures[0]junk".parse::<FigurePath>().is_err());
    }
}
