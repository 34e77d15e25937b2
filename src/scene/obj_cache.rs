//! Large OBJ files' geometry kept on disk: the positions, the triangles and the statements (`o`, `g`, `mtllib`,
//! `usemtl`) that reading the text gave, so that the same text loads again without being read line by line (the
//! 2.3 MB knot: about 10 ms of its load on two cores). The statements are settled again from the entry (the MTL
//! files read anew), so an edited MTL file is seen.
//!
//! An entry is found by a 128-bit XXH3 hash of the text, this format's version and the program's identity
//! ([`DiskCache::hasher`]). It holds the counts, the positions, the triangles and the statements (their names as
//! byte ranges of the text), then their XXH3 checksum; it is used only if its sizes agree with its counts, its
//! checksum with its contents, every corner names a position, the statements are in file order and every name is
//! a range of the text on character boundaries. Where: `objs` in the user's cache folder
//! ([`DiskCache::in_user_cache`]).

use super::disk_cache::{DiskCache, check_sum, entry_head, write_sections};
use super::obj::{Parsed, Statement};
use rayon::prelude::*;
use std::io::{Read, Write};
use std::sync::OnceLock;

/// Raised whenever an entry's layout changes (a change of the reader is a change of the program's identity).
const FORMAT: u32 = 1;

/// The first bytes of an entry.
const MAGIC: [u8; 16] = *b"illumlab obj\0\0\0\0";

/// The header: magic, format and key (9 words), one of padding, the counts of positions, triangles and statements
/// (as u64).
const HEADER_WORDS: usize = 4 + 1 + 4 + 1 + 6;

/// A folder of read OBJ texts.
#[derive(Clone, Debug)]
pub struct ObjCache {
    disk: DiskCache,
}

impl ObjCache {
    /// Smaller texts are read every time: a few milliseconds or less.
    pub const MIN_BYTES: usize = 1 << 20;

    #[cfg(test)]
    pub fn new(dir: impl Into<std::path::PathBuf>) -> Self {
        Self { disk: DiskCache::new(dir, "obj") }
    }

    /// `objs` in the user's cache folder, unless the environment turns caches off; read once per process.
    pub fn from_env() -> Option<&'static ObjCache> {
        static CACHE: OnceLock<Option<ObjCache>> = OnceLock::new();
        CACHE.get_or_init(|| DiskCache::in_user_cache("objs", "obj").map(|disk| ObjCache { disk })).as_ref()
    }

    /// The key of what reading `text` gives.
    pub fn key(text: &str) -> u128 {
        let mut hash = DiskCache::hasher();
        hash.update(&MAGIC);
        hash.update(&FORMAT.to_le_bytes());
        hash.update(text.as_bytes());
        hash.digest128()
    }

    /// What reading `text` gave, stored under `key`, if there is a sound entry.
    pub fn load<'a>(&self, key: u128, text: &'a str) -> Option<Parsed<'a>> {
        let (mut file, bytes) = self.disk.open(key)?;
        read_entry(&mut file, bytes, key, text)
    }

    /// Stores what reading `text` gave under `key`.
    pub fn store(&self, key: u128, parsed: &Parsed, text: &str) -> std::io::Result<()> {
        self.disk.store(key, |out| write_entry(out, key, parsed, text))
    }
}

fn header(key: u128, positions: usize, triangles: usize, statements: usize) -> [u32; HEADER_WORDS] {
    let mut words = [0; HEADER_WORDS];
    words[..9].copy_from_slice(&entry_head(MAGIC, FORMAT, key));
    for (k, count) in [positions, triangles, statements].into_iter().enumerate() {
        words[10 + 2 * k] = count as u32;
        words[11 + 2 * k] = (count as u64 >> 32) as u32;
    }
    words
}

/// A statement as four numbers: the triangles above it, its kind, and its name's start and end in the text.
fn statement_words((first, statement): &(usize, Statement), text: &str) -> [u64; 4] {
    let (kind, name) = match *statement {
        Statement::Object(name) => (0, name),
        Statement::Mtllib(name) => (1, name),
        Statement::Usemtl(name) => (2, name),
    };
    let start = name.as_ptr() as usize - text.as_ptr() as usize;
    [*first as u64, kind, start as u64, (start + name.len()) as u64]
}

fn write_entry(out: &mut dyn Write, key: u128, parsed: &Parsed, text: &str) -> std::io::Result<()> {
    let counts = (parsed.positions.len(), parsed.triangles.len(), parsed.statements.len());
    let head = header(key, counts.0, counts.1, counts.2);
    let statements: Vec<[u64; 4]> = parsed.statements.iter().map(|s| statement_words(s, text)).collect();
    write_sections(out, &sections(&head, parsed, &statements))
}

/// An entry's sections in order, as bytes: the header, the positions, the triangles and the statements; the file
/// ends with their XXH3 checksum.
fn sections<'a>(head: &'a [u32; HEADER_WORDS], parsed: &'a Parsed, statements: &'a [[u64; 4]]) -> [&'a [u8]; 4] {
    [
        bytemuck::cast_slice(head),
        bytemuck::cast_slice(&parsed.positions),
        bytemuck::cast_slice(&parsed.triangles),
        bytemuck::cast_slice(statements),
    ]
}

fn read_entry<'a>(file: &mut impl Read, bytes: u64, key: u128, text: &'a str) -> Option<Parsed<'a>> {
    let mut head = [0u32; HEADER_WORDS];
    file.read_exact(bytemuck::cast_slice_mut(&mut head)).ok()?;
    let count = |k: usize| usize::try_from(u64::from(head[10 + 2 * k]) | u64::from(head[11 + 2 * k]) << 32).ok();
    let (positions, triangles, statements) = (count(0)?, count(1)?, count(2)?);
    // Each position, triangle and statement took at least a few bytes of the text.
    if head != header(key, positions, triangles, statements) || positions.max(triangles).max(statements) > text.len() {
        return None;
    }
    let expected = size_of_val(&head) + positions * 24 + triangles * 12 + statements * 32 + 8;
    if bytes != expected as u64 {
        return None;
    }
    let mut parsed = Parsed {
        positions: bytemuck::zeroed_vec(positions),
        triangles: bytemuck::zeroed_vec(triangles),
        statements: Vec::with_capacity(statements),
    };
    let mut words: Vec<[u64; 4]> = bytemuck::zeroed_vec(statements);
    file.read_exact(bytemuck::cast_slice_mut(&mut parsed.positions)).ok()?;
    file.read_exact(bytemuck::cast_slice_mut(&mut parsed.triangles)).ok()?;
    file.read_exact(bytemuck::cast_slice_mut(&mut words)).ok()?;
    check_sum(file, &sections(&head, &parsed, &words))?;
    if parsed.triangles.par_iter().any(|t| t.iter().any(|&i| i as usize >= positions)) {
        return None;
    }
    let mut above = 0;
    for &[first, kind, start, end] in &words {
        let name = text.get(usize::try_from(start).ok()?..usize::try_from(end).ok()?)?;
        if first < above || first > triangles as u64 {
            return None;
        }
        above = first;
        let statement = match kind {
            0 => Statement::Object(name),
            1 => Statement::Mtllib(name),
            2 => Statement::Usemtl(name),
            _ => return None,
        };
        parsed.statements.push((first as usize, statement));
    }
    Some(parsed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneError;
    use std::fs;
    use std::path::Path;

    /// A text of `n` quads in two objects and two materials, with relative corners, comments and CRLF line ends.
    fn text(n: usize) -> String {
        let mut text = String::from("mtllib a.mtl\r\no first\nusemtl red\n");
        for i in 0..n {
            if i == n / 2 {
                text += "g second # the rest\nusemtl white\n";
            }
            text += &format!("v {i} 0 0\nv {i} 1 0\nv {i}.5 1 0.25\nv {i}.5 0 -1e-3\nf -4 -3 -2 -1\r\n");
        }
        text
    }

    fn materials(_: &str) -> Result<Vec<tobj::Material>, SceneError> {
        let mtl = "newmtl red\nKd 1 0 0\nnewmtl white\nKd 1 1 1\n";
        Ok(tobj::load_mtl_buf(&mut mtl.as_bytes()).unwrap().0)
    }

    fn parse(text: &str) -> Parsed<'_> {
        super::super::obj::parse(text, Path::new("t.obj")).unwrap()
    }

    fn assert_same(a: &Parsed, b: &Parsed) {
        assert!(a.positions == b.positions && a.triangles == b.triangles && a.statements == b.statements);
    }

    #[test]
    fn a_stored_text_reads_back_as_it_was_read() {
        let dir = tempfile::tempdir().unwrap();
        let cache = ObjCache::new(dir.path());
        let text = text(500);
        let key = ObjCache::key(&text);
        assert!(cache.load(key, &text).is_none(), "nothing stored yet");
        let read = parse(&text);
        cache.store(key, &read, &text).unwrap();
        let back = cache.load(key, &text).expect("stored");
        assert_same(&back, &read);
        assert_eq!(back.statements.len(), 5, "mtllib, o, usemtl, g, usemtl");
        // Settled again, the runs are those of the text read line by line.
        let settle = |parsed| super::super::obj::settle(parsed, materials).unwrap();
        let (a, b) = (settle(read), settle(back));
        assert_eq!(format!("{:?}", a.runs), format!("{:?}", b.runs));
        let mut edited = text.clone();
        edited.replace_range(0..1, "M");
        assert!(ObjCache::key(&edited) != key, "another text is another key");
    }

    #[test]
    fn a_damaged_entry_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let cache = ObjCache::new(dir.path());
        let text = text(300);
        let key = ObjCache::key(&text);
        cache.store(key, &parse(&text), &text).unwrap();
        let path = cache.disk.path(key);
        let good = fs::read(&path).unwrap();
        for at in [0, 17, 40, 64, 64 + 24 * 300, good.len() - 40, good.len() - 1] {
            let mut bad = good.clone();
            bad[at] ^= 0x01;
            fs::write(&path, &bad).unwrap();
            assert!(cache.load(key, &text).is_none(), "flipped at {at}");
        }
        for len in [0, 63, good.len() - 8, good.len() - 1] {
            fs::write(&path, &good[..len]).unwrap();
            assert!(cache.load(key, &text).is_none(), "cut at {len}");
        }
        // A sound checksum over unsound contents: a corner past the positions, a name off the text.
        let mut parsed = parse(&text);
        parsed.triangles[5][1] = parsed.positions.len() as u32;
        cache.store(key, &parsed, &text).unwrap();
        assert!(cache.load(key, &text).is_none(), "a corner past the positions");
        let shorter = &text[..text.len() / 4];
        let parsed = parse(&text);
        cache.store(key, &parsed, &text).unwrap();
        assert!(cache.load(key, shorter).is_none(), "names past the end of another text");
    }
}
