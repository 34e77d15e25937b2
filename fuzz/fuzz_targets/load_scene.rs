//! Any bytes, read as a scene's TOML, OBJ and MTL (separated by NUL bytes), either load or fail with an error,
//! never a panic; what loads renders one sample per pixel of a 2×2 image with every strategy, all finite.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    illumlab::fuzz::load_and_render(data);
});
