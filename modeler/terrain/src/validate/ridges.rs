//! The ridgelines and ridgeline trees: their own check (`crate::ridge::layer::skeletons`) and
//! its typed error, [`RidgeError`](crate::ridge::RidgeError).

use super::ValidationError;
use crate::document::Document;

/// Checks the ridgelines and trees (`crate::ridge::layer::skeletons`): at least two points
/// each, finite numbers, trees without cycles and connected, slopes strictly between 0° and
/// 90°, filter parameters up to 64.
pub fn ridges(doc: &Document) -> Result<(), ValidationError> {
    match &doc.ridges {
        Some(r) => crate::ridge::layer::skeletons(r)
            .map(|_| ())
            .map_err(|e| ValidationError::new("ridges", e)),
        None => Ok(()),
    }
}
