//! The trees' level of detail held to a real-time view's budget.

use penmodel_render::Scene;
use penmodel_terrain::Heightmap;
use penmodel_terrain::revision::Revisions;

use super::scene;
use crate::picture::Picture;

/// The longest a latched frame's view should take, ms. Drawn before the head's pose and moved to
/// it after (`Renderer::reproject`), the view is no longer in the head's latency, but it is most
/// of the frame's period (15 ms and the latch's wait: about 50 frames a second), and the older the
/// pose it was drawn from, the more its reprojection moves and uncovers. (It was the 20 ms from
/// the head's emission to the frame, issue 16, less the chain's own 4.6 ms, when the view was
/// drawn after the latch.)
pub const VIEW_BUDGET_MS: f64 = 15.0;

/// The trees' level of detail held to the view's budget in real time: after a view over
/// [`VIEW_BUDGET_MS`] the roughness at the gaze, `Q0`, is raised by half (up to the seed's
/// `Q ≈ 0.10` its subjects accepted for small trees); after one under 60 % of it, lowered by a
/// fifth back towards the default. This is the seed's own lever: its Q was chosen to hold a frame
/// time. A grove planted under the pen, at `Q0` = 0.02 by the gaze, drew 38 000 polygons and
/// 26 000 simplified shapes for four frames of 44–72 ms. Only latched frames use it: the
/// unpaced demo's frames stay the same from run to run.
#[derive(Debug, Clone, Copy)]
pub struct TreeBudget {
    /// `Q0` over its default.
    scale: f64,
}

impl TreeBudget {
    /// The largest `Q0`.
    pub const MAX_Q0: f64 = 0.10;

    /// The default detail.
    pub fn new() -> TreeBudget {
        TreeBudget { scale: 1.0 }
    }

    /// `roughness` with this budget's `Q0`.
    pub fn apply(&self, roughness: penmodel_terrain::trees::Roughness) -> penmodel_terrain::trees::Roughness {
        penmodel_terrain::trees::Roughness {
            q0: (roughness.q0 * self.scale).min(Self::MAX_Q0.max(roughness.q0)),
            ..roughness
        }
    }

    /// [`scene`] with the trees at this budget's detail.
    pub fn scene<'a>(&self, p: &'a Picture, map: &'a Heightmap, revisions: Option<&'a Revisions>) -> Scene<'a> {
        let mut scene = scene(p, map, revisions);
        scene.tree_lod = scene.tree_lod.map(|r| self.apply(r));
        scene
    }

    /// Takes a view that took `ms`.
    pub fn after(&mut self, ms: f64) {
        let max = Self::MAX_Q0 / penmodel_terrain::trees::Roughness::default().q0;
        if ms > VIEW_BUDGET_MS {
            self.scale = (self.scale * 1.5).min(max);
        } else if ms < 0.6 * VIEW_BUDGET_MS {
            self.scale = (self.scale / 1.2).max(1.0);
        }
    }
}

impl Default for TreeBudget {
    fn default() -> TreeBudget {
        TreeBudget::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_trees_budget_coarsens_late_views_and_recovers() {
        use penmodel_terrain::trees::Roughness;
        let mut b = TreeBudget::new();
        let q0 = Roughness::default().q0;
        assert_eq!(b.apply(Roughness::default()).q0, q0);
        b.after(VIEW_BUDGET_MS + 1.0);
        assert!((b.apply(Roughness::default()).q0 - 1.5 * q0).abs() < 1e-12);
        for _ in 0..20 {
            b.after(3.0 * VIEW_BUDGET_MS);
        }
        assert_eq!(b.apply(Roughness::default()).q0, TreeBudget::MAX_Q0);
        // Within the budget but over 60 % of it: held.
        b.after(0.8 * VIEW_BUDGET_MS);
        assert_eq!(b.apply(Roughness::default()).q0, TreeBudget::MAX_Q0);
        for _ in 0..20 {
            b.after(0.1 * VIEW_BUDGET_MS);
        }
        assert_eq!(b.apply(Roughness::default()).q0, q0);
        // A scene asking for coarser trees than the budget's most keeps its own.
        let coarse = Roughness {
            q0: 0.3,
            ..Roughness::default()
        };
        b.after(3.0 * VIEW_BUDGET_MS);
        assert_eq!(b.apply(coarse).q0, 0.3);
    }
}
