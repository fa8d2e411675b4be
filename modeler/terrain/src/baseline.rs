//! The seed's distance maps, computed as the thesis does: sweep the whole grid again and again
//! until nothing changes (section 4.3). O(cells × largest distance) against the breadth-first
//! searches' O(cells). Kept as the reference the fast maps are tested against, and as the
//! benchmark baseline.
//!
//! Each sweep is synchronous: values assigned during a sweep are read only by the next one. That
//! is the reading under which the thesis' rules give true 4-neighbour distances (an in-place sweep
//! would let a value travel several cells in one pass and fix it too early).

use crate::cells::{Cell, Mask};
use crate::distance::{UNREACHABLE, neighbours};

/// `dp` by repeated sweeps: (1) the figure's cells hold 0; (2) a region cell without a value next
/// to a cell with one takes that value + 1; (3) repeat until no cell changes.
pub fn from_sources(mask: &Mask, sources: &[Cell]) -> Vec<u32> {
    let bits = mask.bits();
    let mut dist = vec![UNREACHABLE; mask.box_len()];
    for &s in sources {
        if let Some(i) = mask.index(s).filter(|&i| bits[i]) {
            dist[i] = 0;
        }
    }
    let mut sweep = 1u32;
    loop {
        let mut changed = false;
        for i in 0..dist.len() {
            // Only values from earlier sweeps propagate.
            if dist[i] < sweep {
                for j in neighbours(mask, i).into_iter().flatten() {
                    if bits[j] && dist[j] == UNREACHABLE {
                        dist[j] = dist[i] + 1;
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            return dist;
        }
        sweep += 1;
    }
}

/// `df` by repeated sweeps: (1) every region cell holds 0; (2) a cell whose four neighbours all
/// hold the same value v becomes v + 1 (a neighbour outside the region holds no value); (3)
/// repeat until no cell changes.
pub fn edge_layers(mask: &Mask) -> Vec<u32> {
    let bits = mask.bits();
    let mut dist: Vec<u32> = bits.iter().map(|&b| if b { 0 } else { UNREACHABLE }).collect();
    let mut next = dist.clone();
    loop {
        let mut changed = false;
        for i in 0..dist.len() {
            if !bits[i] {
                continue;
            }
            let ns = neighbours(mask, i);
            let Some(Some(first)) = ns.first().copied() else {
                continue;
            };
            let v = dist[first];
            let all_same = ns.iter().all(|n| n.is_some_and(|j| bits[j] && dist[j] == v));
            if all_same && v != UNREACHABLE && dist[i] != v + 1 {
                next[i] = v + 1;
                changed = true;
            }
        }
        if !changed {
            return dist;
        }
        dist.copy_from_slice(&next);
    }
}

/// The terrain of `doc` with every distance map computed by the sweeps above: the same numbers
/// as [`crate::generate`], the seed's cost.
pub fn generate(doc: &crate::Document) -> Result<crate::Heightmap, crate::ValidationError> {
    Ok(
        crate::engine::TerrainEngine::with_method(doc.clone(), crate::engine::Method::Sweep)?
            .into_parts()
            .1,
    )
}
