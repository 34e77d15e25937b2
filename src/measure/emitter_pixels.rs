//! The pixels whose footprint sees an emitter directly. There the value is dominated by L_e, which no strategy
//! estimates (every one adds the same L_e of the primary hit), and with a jittered footprint by the light's
//! outline: the bench leaves them out of the error, and reports how many.

use crate::render::Footprint;
use crate::scene::Scene;
use glam::Vec2;

/// Per pixel (row 0 first): whether a camera ray through it meets an emitting triangle first. For the centre
/// footprint, the ray through the centre; for the jittered one, any of a 5 × 5 grid over the pixel, corners and
/// edges included.
pub fn sees_emitter(scene: &Scene, footprint: Footprint) -> Vec<bool> {
    let camera = scene.camera.basis();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let positions: Vec<Vec2> = match footprint {
        Footprint::Centre => vec![Vec2::splat(0.5)],
        Footprint::Jittered => (0..25).map(|i| Vec2::new((i % 5) as f32, (i / 5) as f32) * 0.25).collect(),
    };
    let emits = |t: u32| scene.material_of(t).is_emissive();
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            positions.iter().any(|&at| {
                let dir = camera.direction(x, y, at);
                scene.accel().closest_hit(camera.eye(), dir, f32::INFINITY).is_some_and(|hit| emits(hit.triangle))
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    /// In the Cornell box the ceiling light is a few percent of the image; the jittered footprint adds its
    /// outline's pixels to the centres'.
    #[test]
    fn the_cornell_boxs_light_is_a_few_percent_of_its_pixels() {
        let mut scene = load_scene("cornell-box").expect("bundled");
        (scene.camera.width, scene.camera.height) = (64, 64);
        let centre = sees_emitter(&scene, Footprint::Centre);
        let jittered = sees_emitter(&scene, Footprint::Jittered);
        let count = |v: &[bool]| v.iter().filter(|&&b| b).count();
        assert!((20..400).contains(&count(&centre)), "{}", count(&centre));
        assert!(count(&jittered) > count(&centre));
        assert!(centre.iter().zip(&jittered).all(|(c, j)| !c || *j), "a centre that sees it is in the footprint");
    }
}
