//! Per pixel, the few triangles its camera rays can hit (`Accel::cone_triangles`), found on the first pass that
//! needs them and kept for the later ones: the cull depends only on the scene's geometry and the camera, not on
//! the samples, so a pass of 32 samples per pixel does not walk the tree once per pixel to find them again. Kept
//! as triangle ids (4 bytes a triangle), a row at a time, each row filled by the thread that renders it first.

use crate::scene::{Camera, CameraBasis, ConeCandidates, Scene};
use std::sync::OnceLock;

/// The cones of every pixel of one camera's image, row by row, for one scene geometry (materials may change).
pub struct PixelCones {
    camera: Camera,
    rows: Vec<OnceLock<RowCones>>,
}

/// One row's cones: pixel x's triangles are `ids[ends[x − 1]..ends[x]]` (from 0 for x = 0), or [`NO_CONE`]
/// alone for a pixel whose rays can hit more than eight triangles.
struct RowCones {
    ends: Vec<u32>,
    ids: Vec<u32>,
}

/// Marks a pixel without a cone: no triangle has this id (`Scene::triangles` has fewer).
const NO_CONE: u32 = u32::MAX;

impl PixelCones {
    /// None found yet.
    pub fn new(camera: &Camera) -> Self {
        Self { camera: *camera, rows: (0..camera.height).map(|_| OnceLock::new()).collect() }
    }

    /// The camera whose pixels these are.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The cone of every pixel of row `y` (of `width` pixels), one at a time: `None` for a pixel whose rays can
    /// hit more than eight triangles. Found on the first call for the row.
    pub(super) fn row<'a>(
        &'a self,
        scene: &'a Scene,
        camera: &'a CameraBasis,
        y: u32,
        width: u32,
    ) -> impl Iterator<Item = Option<ConeCandidates>> + 'a {
        let row = self.rows[y as usize].get_or_init(|| {
            let mut row = RowCones { ends: Vec::with_capacity(width as usize), ids: Vec::new() };
            for x in 0..width {
                match scene.accel().cone_triangles(camera.eye(), camera.pixel_corners(x, y)) {
                    Some(ids) => row.ids.extend_from_slice(&ids),
                    None => row.ids.push(NO_CONE),
                }
                row.ends.push(row.ids.len() as u32);
            }
            row
        });
        let starts = std::iter::once(0).chain(row.ends.iter().copied());
        starts.zip(&row.ends).map(move |(start, &end)| match &row.ids[start as usize..end as usize] {
            [NO_CONE] => None,
            ids => Some(scene.cone(camera.eye(), ids)),
        })
    }
}
