//! Opening files the way desktop users expect: a native dialog (rfd; on Linux the XDG desktop portal) on its own
//! thread, so that the image keeps refining while it is open; drag-and-drop of a scene (`.toml`, `.obj`) or a
//! reference (`.exr`) onto the window; and a short list of recent scene files, kept in the user's config folder.
//! The viewer's side of it (what a dropped or picked file opens) is at the end.

use super::viewer::{UiState, Viewer};
use crate::session::Session;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError, channel};

/// What a dialog or a dropped file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Scene,
    Reference,
}

impl FileKind {
    /// What a dropped file is, by its extension; `None` for anything else.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "toml" | "obj" => Some(FileKind::Scene),
            "exr" => Some(FileKind::Reference),
            _ => None,
        }
    }
}

/// A native file dialog open on its own thread.
pub struct Dialog {
    kind: FileKind,
    answer: Receiver<Option<PathBuf>>,
}

impl Dialog {
    /// Opens the dialog; `notify` wakes the UI when it closes.
    pub fn open(kind: FileKind, start_in: Option<PathBuf>, notify: impl Fn() + Send + 'static) -> Self {
        let (tx, answer) = channel();
        // On Linux the dialog is the desktop portal's, reached over the session's D-Bus: without one there is no
        // dialog, and rfd would answer as if it had been cancelled. Say so instead (the sender is dropped).
        if cfg!(target_os = "linux") && std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_none() {
            return Self { kind, answer };
        }
        std::thread::spawn(move || {
            let mut dialog = rfd::FileDialog::new();
            dialog = match kind {
                FileKind::Scene => dialog.set_title("Open a scene").add_filter("scene", &["toml", "obj"]),
                FileKind::Reference => dialog.set_title("Load a reference").add_filter("OpenEXR", &["exr"]),
            };
            if let Some(dir) = start_in {
                dialog = dialog.set_directory(dir);
            }
            let _ = tx.send(dialog.pick_file());
            notify();
        });
        Self { kind, answer }
    }

    /// `None` while it is open; then what was picked (`Ok(None)`: cancelled). `Err` if the dialog could not
    /// run at all (its thread ended without an answer).
    pub fn poll(&self) -> Option<Result<(FileKind, Option<PathBuf>), String>> {
        match self.answer.try_recv() {
            Ok(path) => Some(Ok((self.kind, path))),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                Some(Err("no file dialog here (it needs the desktop portal on a D-Bus session): type the path, or \
                          drop the file on the window"
                    .into()))
            }
        }
    }
}

/// The recent scene files, newest first, at most [`RecentFiles::MAX`]; saved in `file` if there is one.
#[derive(Debug, Default)]
pub struct RecentFiles {
    pub entries: Vec<String>,
    file: Option<PathBuf>,
}

impl RecentFiles {
    pub const MAX: usize = 8;

    /// `$XDG_CONFIG_HOME/illumlab/recent` (or `~/.config/illumlab/recent`).
    pub fn default_file() -> Option<PathBuf> {
        let config = std::env::var_os("XDG_CONFIG_HOME")
            .map(PathBuf::from)
            .filter(|p| p.is_absolute())
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
        Some(config.join("illumlab").join("recent"))
    }

    /// The list kept in `file` (one path per line; missing or unreadable: empty).
    pub fn load(file: PathBuf) -> Self {
        let text = std::fs::read_to_string(&file).unwrap_or_default();
        let entries = text.lines().filter(|l| !l.trim().is_empty()).take(Self::MAX).map(str::to_owned).collect();
        Self { entries, file: Some(file) }
    }

    /// Puts `path` first and saves the list; `Err` says why it could not be saved (the list still changes).
    pub fn push(&mut self, path: &str) -> Result<(), String> {
        self.entries.retain(|e| e != path);
        self.entries.insert(0, path.to_owned());
        self.entries.truncate(Self::MAX);
        let Some(file) = &self.file else { return Ok(()) };
        let save = || -> std::io::Result<()> {
            if let Some(dir) = file.parent() {
                std::fs::create_dir_all(dir)?;
            }
            std::fs::write(file, self.entries.join("\n") + "\n")
        };
        save().map_err(|e| format!("cannot save the recent files in {}: {e}", file.display()))
    }
}

impl Viewer {
    /// Keeps the recent scene files in `file` (read now, written on every open); without it they last as long
    /// as the window (the tests' viewers).
    pub fn set_recent_file(&mut self, file: PathBuf) {
        self.ui.recent = RecentFiles::load(file);
    }

    /// The recent scene files, newest first.
    pub fn recent_files(&self) -> &[String] {
        &self.ui.recent.entries
    }

    /// Keeps the UI's zoom in `file` (read now, written when Ctrl + / − changes it).
    pub fn set_ui_scale_file(&mut self, file: PathBuf) {
        self.ui.ui_scale = UiScale::load(file);
    }
}

/// The UI's zoom factor (egui's Ctrl + / − / 0), remembered between runs in a one-line file.
#[derive(Debug, Default)]
pub struct UiScale {
    /// The factor last saved or read (`None`: none yet).
    factor: Option<f32>,
    file: Option<PathBuf>,
    /// The factor read was applied to the context.
    applied: bool,
}

impl UiScale {
    /// `$XDG_CONFIG_HOME/illumlab/ui-scale` (or `~/.config/illumlab/ui-scale`).
    pub fn default_file() -> Option<PathBuf> {
        RecentFiles::default_file().map(|f| f.with_file_name("ui-scale"))
    }

    pub fn load(file: PathBuf) -> Self {
        let factor = std::fs::read_to_string(&file)
            .ok()
            .and_then(|t| t.trim().parse::<f32>().ok())
            .filter(|f| f.is_finite() && (0.2..=5.0).contains(f));
        Self { factor, file: Some(file), applied: false }
    }

    /// Applies the saved factor once; afterwards saves the context's factor whenever it changes.
    pub(super) fn remember(&mut self, ctx: &egui::Context) {
        if !self.applied {
            self.applied = true;
            if let Some(f) = self.factor {
                ctx.set_zoom_factor(f);
                return;
            }
        }
        let now = ctx.zoom_factor();
        if self.factor.is_some_and(|f| f == now) || (self.factor.is_none() && now == 1.0) {
            return;
        }
        self.factor = Some(now);
        if let Some(file) = &self.file {
            if let Some(dir) = file.parent() {
                let _ = std::fs::create_dir_all(dir);
            }
            // Not being able to remember the zoom is no reason to interrupt a lecture.
            let _ = std::fs::write(file, format!("{now}\n"));
        }
    }
}

/// Opens a native file dialog for a scene or a reference; the choice arrives in a later frame.
pub(super) fn open_dialog(u: &mut UiState, kind: FileKind) {
    let start_in = Path::new(u.open_path.trim()).parent().map(Path::to_path_buf);
    let start_in = start_in.filter(|d| d.is_dir());
    u.dialog = Some(Dialog::open(kind, start_in, u.waker()));
}

/// Files dropped on the window: a scene (`.toml`, `.obj`) opens, a reference (`.exr`) loads, a tour (a `.toml`
/// with [[step]] tables) is presented; anything else is an error on screen.
pub(super) fn take_dropped_files(s: &mut Session, u: &mut UiState, ctx: &egui::Context) {
    let dropped = ctx.input(|i| i.raw.dropped_files.clone());
    for file in dropped {
        let path = file.path().to_path_buf();
        open_file(s, u, FileKind::of(&path), path);
    }
    if let Some(dialog) = &u.dialog
        && let Some(answer) = dialog.poll()
    {
        u.dialog = None;
        match answer {
            Ok((kind, Some(path))) => open_file(s, u, Some(kind), path),
            Ok((_, None)) => {}
            Err(e) => u.error = Some(e),
        }
    }
}

fn open_file(s: &mut Session, u: &mut UiState, kind: Option<FileKind>, path: PathBuf) {
    let text = path.to_string_lossy().into_owned();
    match kind {
        Some(FileKind::Scene) if super::tour::is_tour_file(&path) => super::tour::open_tour(s, u, &text),
        Some(FileKind::Scene) => {
            u.open_path = text.clone();
            u.open(text);
        }
        Some(FileKind::Reference) => {
            u.reference_path = text;
            s.load_reference(path);
        }
        None => {
            u.error =
                Some(format!("cannot open {}: drop a scene (.toml or .obj) or a reference (.exr)", path.display()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_are_newest_first_unique_bounded_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("sub/recent");
        let mut recent = RecentFiles::load(file.clone());
        assert!(recent.entries.is_empty());
        for i in 0..10 {
            recent.push(&format!("/scenes/{i}.toml")).unwrap();
        }
        recent.push("/scenes/3.toml").unwrap();
        assert_eq!(recent.entries.len(), RecentFiles::MAX);
        assert_eq!(recent.entries[0], "/scenes/3.toml");
        assert_eq!(recent.entries[1], "/scenes/9.toml");
        assert_eq!(RecentFiles::load(file).entries, recent.entries, "saved and read back");
    }

    #[test]
    fn dropped_files_are_known_by_their_extension() {
        assert_eq!(FileKind::of(Path::new("a/b.TOML")), Some(FileKind::Scene));
        assert_eq!(FileKind::of(Path::new("b.obj")), Some(FileKind::Scene));
        assert_eq!(FileKind::of(Path::new("r.exr")), Some(FileKind::Reference));
        assert_eq!(FileKind::of(Path::new("notes.txt")), None);
        assert_eq!(FileKind::of(Path::new("noext")), None);
    }
}
