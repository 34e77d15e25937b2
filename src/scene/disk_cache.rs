//! Folders of files that spare a repeated load its work (the built trees of large meshes, `accel::TreeCache`; the
//! parsed geometry of large OBJ files, `obj_cache`), in illumlab's folder of the user's cache. Each entry is named
//! by a 128-bit key, a hash of everything that made it and of the program's identity ([`DiskCache::hasher`]), so
//! an entry is never read by a program that would have made something else of the same input. Entries are written
//! whole under a temporary name, then renamed; each folder is kept under [`CACHE_BYTES`], the entries used least
//! recently removed first. What an entry holds, and the checks it passes before it is used, are its format's.
//!
//! `ILLUMLAB_CACHE=off` in the environment turns these caches off.

use std::fs;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::SystemTime;
use xxhash_rust::xxh3::Xxh3;

/// The most one folder's entries may take together.
pub const CACHE_BYTES: u64 = 1 << 30;

/// A folder of entries, files named `<key>.<extension>`.
#[derive(Clone, Debug)]
pub struct DiskCache {
    dir: PathBuf,
    extension: &'static str,
}

/// illumlab's folder in the user's cache: `$XDG_CACHE_HOME/illumlab`, else `~/.cache/illumlab`.
pub fn user_cache_folder() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    let base = var("XDG_CACHE_HOME").or_else(|| var("HOME").map(|home| home.join(".cache")))?;
    Some(base.join("illumlab"))
}

impl DiskCache {
    pub fn new(dir: impl Into<PathBuf>, extension: &'static str) -> Self {
        Self { dir: dir.into(), extension }
    }

    /// The folder `name` in [`user_cache_folder`], unless `ILLUMLAB_CACHE` is `off`.
    pub fn in_user_cache(name: &str, extension: &'static str) -> Option<Self> {
        let off = std::env::var("ILLUMLAB_CACHE").is_ok_and(|v| v.eq_ignore_ascii_case("off"));
        let folder = user_cache_folder().filter(|_| !off)?;
        Some(Self::new(folder.join(name), extension))
    }

    /// A hasher for keys, fed the program's identity already: its version and its executable's path, size and
    /// modification time (a rebuilt or upgraded illumlab finds no entry of another build).
    pub fn hasher() -> Xxh3 {
        static IDENTITY: OnceLock<String> = OnceLock::new();
        let identity = IDENTITY.get_or_init(|| {
            let exe = std::env::current_exe().ok();
            let meta = exe.as_ref().and_then(|e| fs::metadata(e).ok());
            let modified = meta.as_ref().and_then(|m| m.modified().ok());
            let since = modified.and_then(|m| m.duration_since(SystemTime::UNIX_EPOCH).ok());
            let nanos = since.map(|m| m.as_nanos()).unwrap_or(0);
            format!("{} {exe:?} {:?} {nanos}", env!("CARGO_PKG_VERSION"), meta.map(|m| m.len()))
        });
        let mut hash = Xxh3::new();
        hash.update(identity.as_bytes());
        hash
    }

    pub(super) fn path(&self, key: u128) -> PathBuf {
        self.dir.join(format!("{key:032x}.{}", self.extension))
    }

    /// The entry stored under `key`, opened, and its length in bytes. Its time of use is set to now, so it is the
    /// last to be removed when the folder is full (a failure to set it only makes it older).
    pub fn open(&self, key: u128) -> Option<(fs::File, u64)> {
        let path = self.path(key);
        let file = fs::File::open(&path).ok()?;
        let bytes = file.metadata().ok()?.len();
        let _ = fs::File::options().write(true).open(&path).and_then(|f| f.set_modified(SystemTime::now()));
        Some((file, bytes))
    }

    /// Stores what `write` writes under `key` (in full, or not at all), then trims the folder to [`CACHE_BYTES`].
    pub fn store(&self, key: u128, write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> std::io::Result<()> {
        fs::create_dir_all(&self.dir)?;
        // A name no other writer uses, in this process or another.
        static WRITES: AtomicU64 = AtomicU64::new(0);
        let write_id = WRITES.fetch_add(1, Ordering::Relaxed);
        let temporary = self.dir.join(format!("{key:032x}.{}-{write_id}.partial", std::process::id()));
        let written = fs::File::create(&temporary).and_then(|f| {
            let mut out = std::io::BufWriter::new(f);
            write(&mut out)?;
            out.flush()
        });
        match written.and_then(|()| fs::rename(&temporary, self.path(key))) {
            Ok(()) => self.trim(CACHE_BYTES),
            Err(e) => {
                let _ = fs::remove_file(&temporary);
                Err(e)
            }
        }
    }

    /// Removes the entries used least recently (and partial files left for an hour) until the rest take at most
    /// `limit` bytes.
    fn trim(&self, limit: u64) -> std::io::Result<()> {
        let mut entries = Vec::new();
        let suffix = format!(".{}", self.extension);
        for entry in fs::read_dir(&self.dir)? {
            let entry = entry?;
            let (name, meta) = (entry.file_name(), entry.metadata()?);
            let name = name.to_string_lossy();
            let age = meta.modified().ok().and_then(|m| SystemTime::now().duration_since(m).ok());
            if name.ends_with(".partial") && age.is_some_and(|a| a.as_secs() > 3600) {
                let _ = fs::remove_file(entry.path());
            } else if name.ends_with(&suffix) {
                entries.push((meta.modified().unwrap_or(SystemTime::UNIX_EPOCH), meta.len(), entry.path()));
            }
        }
        entries.sort();
        let mut total: u64 = entries.iter().map(|e| e.1).sum();
        for (_, len, path) in entries {
            if total <= limit {
                break;
            }
            fs::remove_file(path)?;
            total -= len;
        }
        Ok(())
    }
}

/// The first nine words of an entry: its format's magic (16 bytes) and version, and the entry's key.
pub fn entry_head(magic: [u8; 16], format: u32, key: u128) -> [u32; 9] {
    let mut words = [0; 9];
    words[..4].copy_from_slice(&bytemuck::cast::<_, [u32; 4]>(magic));
    words[4] = format;
    words[5..].copy_from_slice(&bytemuck::cast::<_, [u32; 4]>(key.to_le_bytes()));
    words
}

/// Writes an entry's `sections` one after another, then their XXH3 checksum (8 bytes).
pub fn write_sections(out: &mut dyn Write, sections: &[&[u8]]) -> std::io::Result<()> {
    let mut sum = Xxh3::new();
    for section in sections {
        sum.update(section);
        out.write_all(section)?;
    }
    out.write_all(&sum.digest().to_le_bytes())
}

/// `Some` if the next eight bytes of `file` are the XXH3 checksum of `sections` (read before them).
pub fn check_sum(file: &mut impl Read, sections: &[&[u8]]) -> Option<()> {
    let mut stored = [0u8; 8];
    file.read_exact(&mut stored).ok()?;
    let mut sum = Xxh3::new();
    for section in sections {
        sum.update(section);
    }
    (sum.digest() == u64::from_le_bytes(stored)).then_some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_entry_is_written_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let cache = DiskCache::new(dir.path(), "test");
        cache.store(7, |out| out.write_all(b"whole")).unwrap();
        let failed = cache.store(8, |out| {
            out.write_all(b"half")?;
            Err(std::io::Error::other("the writer failed"))
        });
        assert!(failed.is_err());
        let (file, bytes) = cache.open(7).expect("stored");
        assert_eq!((std::io::read_to_string(file).unwrap().as_str(), bytes), ("whole", 5));
        assert!(cache.open(8).is_none());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "no partial file is left");
    }

    #[test]
    fn the_folder_keeps_the_entries_used_last() {
        let dir = tempfile::tempdir().unwrap();
        let cache = DiskCache::new(dir.path(), "tree");
        let now = SystemTime::now();
        for (i, age) in [30u64, 10, 20].into_iter().enumerate() {
            let path = dir.path().join(format!("{i}.tree"));
            fs::write(&path, [0u8; 100]).unwrap();
            let when = now - std::time::Duration::from_secs(age);
            fs::File::options().write(true).open(&path).unwrap().set_modified(when).unwrap();
        }
        fs::write(dir.path().join("other.txt"), [0u8; 1000]).unwrap();
        cache.trim(250).unwrap();
        let mut left: Vec<String> =
            fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
        left.sort();
        assert_eq!(left, ["1.tree", "2.tree", "other.txt"], "the oldest entry goes; other files stay");
    }
}
