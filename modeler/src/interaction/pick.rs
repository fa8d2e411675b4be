//! What is under the pen: the seed's selection rule, and where a new figure belongs.
//!
//! A point figure is under the tip when the tip is near it, a polyline when the tip is near the
//! line, a closed curve when the tip is inside it (or near its outline). A region's boundary is
//! picked only near the line: inside a region is where figures are drawn. When several qualify,
//! the nearest line or point wins; failing that, the innermost closed curve around the tip.

use penmodel_terrain::address::{CurvePath, FigurePath};
use penmodel_terrain::document::{Document, Figure, FigureKind, Point};
use penmodel_terrain::geometry::{Side, distance, locate, segment_distance};

/// A picked curve, and its vertex under the tip if there is one.
#[derive(Debug, Clone, PartialEq)]
pub struct Hit {
    /// The figure or region boundary.
    pub curve: CurvePath,
    /// Its vertex within the tolerance of the tip (vertex indices leave out a closed curve's
    /// repeated last point).
    pub vertex: Option<usize>,
}

/// Distance from `p` to a polyline (or a single point).
pub fn line_distance(points: &[Point], p: Point) -> f64 {
    match points {
        [] => f64::INFINITY,
        [only] => distance(*only, p),
        _ => points
            .windows(2)
            .map(|s| segment_distance(s[0], s[1], p))
            .fold(f64::INFINITY, f64::min),
    }
}

/// The vertex of `points` nearest `p` within `tolerance`.
fn vertex_near(points: &[Point], closed: bool, p: Point, tolerance: f64) -> Option<usize> {
    let n = if closed {
        points.len().saturating_sub(1)
    } else {
        points.len()
    };
    (0..n)
        .map(|i| (i, distance(points[i], p)))
        .filter(|&(_, d)| d <= tolerance)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

struct Best {
    /// The nearest line or point within the tolerance.
    near: Option<(f64, CurvePath)>,
    /// The deepest closed figure around the tip.
    inside: Option<(usize, FigurePath)>,
}

impl Best {
    fn offer_near(&mut self, d: f64, curve: CurvePath) {
        if self.near.as_ref().is_none_or(|(best, _)| d < *best) {
            self.near = Some((d, curve));
        }
    }
}

fn visit(figures: &[Figure], path: &dyn Fn(usize) -> FigurePath, depth: usize, p: Point, tol: f64, best: &mut Best) {
    for (i, f) in figures.iter().enumerate() {
        let here = path(i);
        let d = line_distance(&f.points, p);
        if d <= tol {
            best.offer_near(d, CurvePath::Figure(here.clone()));
        }
        if f.kind == FigureKind::Closed {
            let around = locate(&f.points, p) != Side::Outside;
            if around && best.inside.as_ref().is_none_or(|(deepest, _)| depth > *deepest) {
                best.inside = Some((depth, here.clone()));
            }
            // Lines nested inside may come within the tolerance even from outside the curve.
            let nested = |j: usize| here.child(j);
            visit(&f.figures, &nested, depth + 1, p, tol, best);
        }
    }
}

/// The figure or boundary under ground point `p`, with lines and points within `tolerance`
/// metres.
pub fn pick(doc: &Document, p: Point, tolerance: f64) -> Option<Hit> {
    let mut best = Best {
        near: None,
        inside: None,
    };
    for (r, region) in doc.regions.iter().enumerate() {
        let d = line_distance(&region.boundary, p);
        if d <= tolerance {
            best.offer_near(d, CurvePath::Boundary(r));
        }
        let path = |i: usize| FigurePath::new(r, i);
        visit(&region.figures, &path, 0, p, tolerance, &mut best);
    }
    let curve = match (best.near, best.inside) {
        (Some((_, c)), _) => c,
        (None, Some((_, f))) => CurvePath::Figure(f),
        (None, None) => return None,
    };
    let vertex = match &curve {
        CurvePath::Boundary(r) => vertex_near(&doc.regions[*r].boundary, true, p, tolerance),
        CurvePath::Figure(at) => at
            .get(doc)
            .and_then(|f| vertex_near(&f.points, f.kind == FigureKind::Closed, p, tolerance)),
    };
    Some(Hit { curve, vertex })
}

/// Where a new figure with these points goes: the list of the innermost closed figure, or of the
/// top-level region, that has every point strictly inside; `None` when no region does.
pub fn container(doc: &Document, points: &[Point]) -> Option<FigurePath> {
    let all_inside = |ring: &[Point]| points.iter().all(|&q| locate(ring, q) == Side::Inside);
    let r = doc.regions.iter().position(|region| all_inside(&region.boundary))?;
    // The new figure's path: index at the end of the list it joins.
    let mut list = &doc.regions[r].figures;
    let mut at = FigurePath::new(r, list.len());
    loop {
        let Some(i) = list
            .iter()
            .position(|f| f.kind == FigureKind::Closed && all_inside(&f.points))
        else {
            return Some(at);
        };
        let parent = at.parent().map_or_else(|| FigurePath::new(r, i), |p| p.child(i));
        list = &list[i].figures;
        at = parent.child(list.len());
    }
}

/// The height a new figure starts at: the base of the region it joins (its enclosing closed
/// figure's height, or 0 at the top level), so that adding it raises nothing by itself.
pub fn base_height(doc: &Document, at: &FigurePath) -> f64 {
    at.parent().and_then(|p| p.get(doc)).map_or(0.0, |f| f.height)
}

#[cfg(test)]
mod tests {
    use super::*;
    use penmodel_terrain::document::{Grid, Region};

    fn square(x0: f64, y0: f64, side: f64) -> Vec<Point> {
        vec![
            [x0, y0],
            [x0 + side, y0],
            [x0 + side, y0 + side],
            [x0, y0 + side],
            [x0, y0],
        ]
    }

    fn figure(kind: FigureKind, points: Vec<Point>, figures: Vec<Figure>) -> Figure {
        Figure {
            kind,
            points,
            height: 0.0,
            slope: 0.0,
            figures,
        }
    }

    fn doc() -> Document {
        let mut d = Document::new(Grid {
            cols: 100,
            rows: 100,
            cell_size: 1.0,
        });
        d.regions.push(Region {
            metric: None,
            boundary: square(5.0, 5.0, 90.0),
            figures: vec![
                figure(FigureKind::Point, vec![[20.0, 20.0]], vec![]),
                figure(FigureKind::Polyline, vec![[30.0, 20.0], [60.0, 20.0]], vec![]),
                figure(
                    FigureKind::Closed,
                    square(40.0, 40.0, 40.0),
                    vec![figure(FigureKind::Point, vec![[60.0, 60.0]], vec![])],
                ),
            ],
        });
        d
    }

    #[test]
    fn the_seed_selection_rule() {
        let d = doc();
        let at = |p: Point| pick(&d, p, 2.0).map(|h| (h.curve.to_string(), h.vertex));
        assert_eq!(at([21.0, 20.5]), Some(("regions[0].figures[0]".into(), Some(0))));
        assert_eq!(at([45.0, 21.0]), Some(("regions[0].figures[1]".into(), None)));
        assert_eq!(at([59.5, 19.0]), Some(("regions[0].figures[1]".into(), Some(1))));
        // Inside the closed curve, away from its nested point.
        assert_eq!(at([50.0, 70.0]), Some(("regions[0].figures[2]".into(), None)));
        // The nested point beats its enclosing curve.
        assert_eq!(
            at([60.5, 60.0]),
            Some(("regions[0].figures[2].figures[0]".into(), Some(0)))
        );
        // A region's boundary only near the line; its inside selects nothing.
        assert_eq!(at([5.5, 50.0]), Some(("regions[0].boundary".into(), None)));
        assert_eq!(at([6.0, 94.0]), Some(("regions[0].boundary".into(), Some(3))));
        assert_eq!(at([20.0, 80.0]), None);
        assert_eq!(at([99.0, 99.0]), None);
    }

    #[test]
    fn new_figures_join_the_innermost_closed_curve() {
        let d = doc();
        assert_eq!(
            container(&d, &[[10.0, 10.0], [20.0, 30.0]]).map(|p| p.to_string()),
            Some("regions[0].figures[3]".into())
        );
        assert_eq!(
            container(&d, &[[50.0, 50.0]]).map(|p| p.to_string()),
            Some("regions[0].figures[2].figures[1]".into())
        );
        // Across the closed curve's edge: the region's list (validation decides the rest).
        assert_eq!(
            container(&d, &[[50.0, 50.0], [30.0, 30.0]]).map(|p| p.to_string()),
            Some("regions[0].figures[3]".into())
        );
        assert_eq!(container(&d, &[[1.0, 1.0]]), None);
        let nested = container(&d, &[[50.0, 50.0]]).unwrap();
        let mut d2 = d.clone();
        FigurePath::new(0, 2).get_mut(&mut d2).unwrap().height = 40.0;
        assert_eq!(base_height(&d2, &nested), 40.0);
        assert_eq!(base_height(&d2, &FigurePath::new(0, 3)), 0.0);
    }
}
