//! What the loader's fuzz target (`fuzz/`, cargo-fuzz) runs, and its corpus replay in `cargo test`: any bytes
//! read as a scene's TOML, OBJ and MTL either load or fail with an error, never a panic; a scene that loads
//! renders one sample per pixel of a 2×2 image with every strategy without a panic (a non-finite sample, which
//! extreme but valid values such as `Ke 3e38` can make, is counted and dropped by the renderer, as always).

use crate::render::{Film, RenderSettings, Renderer, Strategy};
use crate::scene::load_scene_from_bytes;
use std::sync::Arc;

/// Panics (the fuzzer's finding) where the loader or a renderer does; returns whether the input loaded.
pub fn load_and_render(data: &[u8]) -> bool {
    let Ok(mut scene) = load_scene_from_bytes(data) else { return false };
    // The camera's own size may be 10⁶ × 10⁶: the image is not what is being tested.
    (scene.camera.width, scene.camera.height) = (2, 2);
    let scene = Arc::new(scene);
    for strategy in Strategy::ALL {
        let mut renderer = Renderer::new(scene.clone(), RenderSettings { strategy, ..Default::default() });
        let mut film = Film::new(2, 2);
        renderer.render_pass(&mut film, 0, 1, &|| false);
    }
    true
}
