//! Per pixel, the few triangles its camera rays can hit (`Accel::cone_triangles`), found on the first pass that
//! needs them and kept for the later ones: the cull depends only on the scene's geometry and the camera, not on
//! the samples, so a pass of 32 samples per pixel does not walk the tree once per pixel to find them again. Kept
//! as triangle ids (4 bytes a triangle), a row at a time, each row filled by the thread that renders it first.

use crate::scene::{Camera, CameraBasis, MAX_CONE, Scene, TileLights};
use std::sync::OnceLock;

/// The cones of every pixel of one camera's image, row by row, and what its tiles' shadow rays can meet
/// ([`TileLights`]), for one scene geometry (materials may change).
pub struct PixelCones {
    camera: Camera,
    rows: Vec<OnceLock<RowCones>>,
    /// Row-major, `camera.width.div_ceil(TILE)` a row.
    tiles: Vec<OnceLock<TileLights>>,
    /// The emitter triangles the tiles' slots stand for (`Scene::emitters` when the first was found): a scene
    /// whose materials changed which triangles emit gets nothing from these tiles.
    lights: OnceLock<Vec<u32>>,
}

/// What a pixel without a cone, or a scene whose emitters changed, knows of its shadow rays: nothing.
static NO_LIGHTS: TileLights = TileLights::NONE;

/// The side of a tile, in pixels: one shaft per light serves TILE² pixels (a pixel's own shaft cost about as
/// much as the shadow rays it saved the Cornell box at 256 samples).
const TILE: u32 = 4;

/// One row's cones: pixel x's triangles are `ids[ends[x − 1]..ends[x]]` (from 0 for x = 0) in
/// `Accel::cone_triangles`' order, or [`NO_CONE`] alone for a pixel whose rays can hit more than [`MAX_CONE`]
/// triangles.
struct RowCones {
    ends: Vec<u32>,
    ids: Vec<u32>,
}

/// Marks a pixel without a cone: no triangle has this id (`Scene::triangles` has fewer).
const NO_CONE: u32 = u32::MAX;

impl PixelCones {
    /// None found yet.
    pub fn new(camera: &Camera) -> Self {
        let tiles = camera.width.div_ceil(TILE) * camera.height.div_ceil(TILE);
        Self {
            camera: *camera,
            rows: (0..camera.height).map(|_| OnceLock::new()).collect(),
            tiles: (0..tiles).map(|_| OnceLock::new()).collect(),
            lights: OnceLock::new(),
        }
    }

    /// The camera whose pixels these are.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The cone of every pixel of row `y` (of `width` pixels), one at a time, as its triangles' ids (for
    /// `Scene::cone`), with its tile's lights: `None` for a pixel whose rays can hit more than [`MAX_CONE`]
    /// triangles, and [`TileLights::NONE`] where they can hit more than eight (the tile's cone, which holds the
    /// pixel's, then has more than eight too). Found on the first call for the row (the lights, for the tile).
    pub(super) fn row<'a>(
        &'a self,
        scene: &'a Scene,
        camera: &'a CameraBasis,
        y: u32,
        width: u32,
    ) -> impl Iterator<Item = (Option<&'a [u32]>, &'a TileLights)> + 'a {
        let row = self.rows[y as usize].get_or_init(|| {
            let mut row = RowCones { ends: Vec::with_capacity(width as usize), ids: Vec::new() };
            for x in 0..width {
                match scene.accel().cone_triangles(camera.eye(), camera.pixel_corners(x, y), MAX_CONE) {
                    Some(ids) => row.ids.extend_from_slice(&ids),
                    None => row.ids.push(NO_CONE),
                }
                row.ends.push(row.ids.len() as u32);
            }
            row
        });
        let starts = std::iter::once(0).chain(row.ends.iter().copied());
        let cones = starts.zip(&row.ends).map(move |(start, &end)| match &row.ids[start as usize..end as usize] {
            [NO_CONE] => (None, false),
            ids => (Some(ids), ids.len() <= 8),
        });
        let tiles = &self.tiles[(y / TILE * width.div_ceil(TILE)) as usize..];
        let same_lights = *self.lights.get_or_init(|| scene.emitters.clone()) == scene.emitters;
        cones.zip(0..width).map(move |((cone, few), x)| {
            let tile =
                || tiles[(x / TILE) as usize].get_or_init(|| self.tile_lights(scene, camera, x / TILE, y / TILE));
            let lights = if few && same_lights { tile() } else { &NO_LIGHTS };
            (cone, lights)
        })
    }

    /// The lights of tile (tx, ty): those of the cone through its outer corners, which holds every cone of its
    /// pixels ([`TileLights::NONE`] where it can hit more than eight triangles).
    fn tile_lights(&self, scene: &Scene, camera: &CameraBasis, tx: u32, ty: u32) -> TileLights {
        let (x0, y0) = (tx * TILE, ty * TILE);
        let (x1, y1) = ((x0 + TILE).min(self.camera.width) - 1, (y0 + TILE).min(self.camera.height) - 1);
        let corners = [
            camera.pixel_corners(x0, y0)[0],
            camera.pixel_corners(x1, y0)[1],
            camera.pixel_corners(x1, y1)[2],
            camera.pixel_corners(x0, y1)[3],
        ];
        scene
            .accel()
            .cone_triangles(camera.eye(), corners, 8)
            .map_or(TileLights::NONE, |ids| scene.tile_lights(camera.eye(), corners, &ids))
    }
}

#[cfg(test)]
mod tests {
    use super::PixelCones;
    use crate::math::SampleRng;
    use crate::math::Vec3x8;
    use crate::render::{SEGMENT_END, ShadingPoint, shadow_ray_ends, visible};
    use crate::sampling::sample_uniform_triangle;
    use crate::scene::every_bundled_scene;
    use glam::Vec2;
    use wide::i32x8;

    /// Every shadow ray a light strategy traces from a pixel to one of its clear lights gets through, and every
    /// one to a light its tile's blockers list is stopped by them exactly when it is stopped, traced as `visible`
    /// traces it: from the hits of jittered camera rays (the pixel's corners among them) to uniform points of the
    /// light and to its corners. And the shafts pay where they should: on the Cornell box, on the default scene
    /// and under near-light's lamp, a good share of those rays go to a clear light, and on the Cornell box and
    /// the default scene a good share of the others meet only their tile's blockers (veach-mis has too many
    /// emitter triangles for shafts; occluded-light's blocker has too many triangles to list).
    #[test]
    fn shadow_rays_to_a_clear_light_all_get_through() {
        let least_share = [("default", 0.3), ("cornell-box", 0.3), ("near-light", 0.9)];
        let least_listed = [("default", 0.3), ("cornell-box", 0.25)];
        for (name, scene, camera) in every_bundled_scene(64, 48) {
            let basis = camera.basis();
            let cones = PixelCones::new(&camera);
            let (mut rays, mut to_clear, mut listed, mut stopped) = (0, 0, 0, 0);
            for y in 0..camera.height {
                for (x, (_, lights)) in (0..camera.width).zip(cones.row(&scene, &basis, y, camera.width)) {
                    let clear = lights.clear;
                    let mut rng = SampleRng::new(11, (y * camera.width + x) as u64, 0);
                    for (slot, &light) in scene.emitters.iter().enumerate().take(32) {
                        let tri = &scene.triangles[light as usize];
                        for k in 0..24 {
                            let jitter = match k {
                                0..4 => Vec2::new((k & 1) as f32, (k >> 1) as f32).min(Vec2::splat(0.999_999_9)),
                                _ => rng.uniform_2d(),
                            };
                            let dir = basis.direction(x, y, jitter);
                            let Some(hit) = scene.accel().closest_hit(basis.eye(), dir, f32::INFINITY) else {
                                continue;
                            };
                            let (on, material) =
                                (&scene.triangles[hit.triangle as usize], scene.material_of(hit.triangle));
                            let sp = ShadingPoint::on_triangle(scene.hit_point(&hit), on, -dir, material);
                            let x_light = match k {
                                0..3 => tri.v[k],
                                _ => sample_uniform_triangle(rng.uniform_2d(), tri.v[0], tri.v[1], tri.v[2]),
                            };
                            // Only the rays a light strategy traces: to the light's front, above the surface.
                            let w = x_light - sp.p;
                            if !(tri.n.dot(-w) > 0.0 && sp.n.dot(w) > 0.0) {
                                continue;
                            }
                            rays += 1;
                            if clear >> slot & 1 != 0 {
                                to_clear += 1;
                                assert!(
                                    visible(&scene, &sp, (light, x_light, tri.n), &mut 0),
                                    "{name}: pixel ({x}, {y}) sees emitter slot {slot} clear, but the ray to {x_light} is stopped"
                                );
                            } else if let Some(b) = lights.blockers.as_deref().filter(|b| b.lights() >> slot & 1 != 0) {
                                listed += 1;
                                let (from, to) = shadow_ray_ends(&scene, sp.p, sp.n, sp.error, (light, x_light, tri.n));
                                let ray = (Vec3x8::splat(from), Vec3x8::splat(to - from));
                                let by_blockers =
                                    b.occluded_lanes(&ray.0, &ray.1, SEGMENT_END, 1, i32x8::splat(slot as i32));
                                let is_visible = visible(&scene, &sp, (light, x_light, tri.n), &mut 0);
                                assert_eq!(
                                    by_blockers == 0,
                                    is_visible,
                                    "{name}: pixel ({x}, {y}), slot {slot}, ray to {x_light}"
                                );
                                stopped += !is_visible as u32;
                            }
                        }
                    }
                }
            }
            let share = to_clear as f64 / rays as f64;
            let listed_share = listed as f64 / (rays - to_clear).max(1) as f64;
            println!(
                "{name}: {to_clear} of {rays} shadow rays go to a clear light ({:.0}%); of the others, {listed} ({:.0}%) \
                 meet only their tile's blockers, {stopped} of them stopped",
                share * 100.0,
                listed_share * 100.0
            );
            if let Some(&(_, least)) = least_share.iter().find(|(n, _)| *n == name) {
                assert!(share >= least, "{name}: only {:.0}% of the shadow rays go to a clear light", share * 100.0);
            }
            if let Some(&(_, least)) = least_listed.iter().find(|(n, _)| *n == name) {
                assert!(listed_share >= least, "{name}: only {:.0}% of the others are listed", listed_share * 100.0);
                assert!(stopped > 0, "{name}: the blockers stop no ray: the test checks too little");
            }
        }
    }

    /// Tiles found for one set of emitter triangles give none of their clear lights to a scene in which other
    /// triangles emit (a material's emission changed; the geometry, and so the cones, did not).
    #[test]
    fn clear_lights_are_kept_for_the_same_emitters_only() {
        let (_, scene, camera) =
            every_bundled_scene(32, 24).find(|(name, ..)| *name == "cornell-box").expect("bundled");
        let (basis, cones) = (camera.basis(), PixelCones::new(&camera));
        let clear = |scene: &crate::scene::Scene| -> u32 {
            (0..camera.height)
                .map(|y| cones.row(scene, &basis, y, camera.width).filter(|(_, l)| l.clear != 0).count() as u32)
                .sum()
        };
        let before = clear(&scene);
        assert!(before > 0, "the Cornell box's walls see its light clear");
        let mut other = scene.clone();
        other.emitters.reverse();
        assert_eq!(clear(&other), 0, "the slots stand for other triangles now");
        assert_eq!(clear(&scene), before);
    }
}
