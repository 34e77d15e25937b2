//! Replays the loader's fuzz corpus (`fuzz/corpus/load_scene`, grown by `cargo +nightly fuzz run load_scene`):
//! every input loads or fails with an error, never a panic, and what loads renders with every strategy.

#[test]
fn every_input_of_the_fuzz_corpus_loads_or_fails_cleanly() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/load_scene");
    let mut inputs: Vec<_> = std::fs::read_dir(&dir).expect("the corpus folder").map(|e| e.unwrap().path()).collect();
    inputs.sort();
    assert!(inputs.len() >= 7, "the corpus holds its seeds at least");
    let mut loaded = 0;
    for path in &inputs {
        let data = std::fs::read(path).unwrap();
        let outcome = std::panic::catch_unwind(|| illumlab::fuzz::load_and_render(&data));
        match outcome {
            Ok(true) => loaded += 1,
            Ok(false) => {}
            Err(_) => panic!("{} panics", path.display()),
        }
    }
    eprintln!("{} inputs, {loaded} loaded and rendered", inputs.len());
    assert!(loaded >= 5, "the seeds that are valid scenes load ({loaded})");
}
