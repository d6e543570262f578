//! Writing outputs so that nothing is ever lost or mixed.
//!
//! - One file: [`write_atomically`] writes it in full to a temporary file beside its
//!   destination, flushes it to disk, then renames it over the destination. A reader sees the
//!   old file or the new one, never half of one.
//! - A set of files that belong together (`mannequin.obj`, `profiles.json`,
//!   `measurements.json`, ...): [`OutputSet`] commits them as a whole. A reader of the output
//!   directory sees the whole old set or the whole new set, never a mix, whenever the writer is
//!   killed or the disk fills up.
//!
//! How a set is committed into a directory `out/` (on Unix): the files are written into a new
//! set directory `out/.dressform/sets/<id>/` and flushed; `out/.dressform/current` is a
//! symbolic link to the set in force, replaced by one `rename` (atomic); each name in `out/`
//! (`out/mannequin.obj`) is a symbolic link to `.dressform/current/<name>`, so every name
//! switches to the new set at that one instant. The old set is removed afterwards; a run
//! killed midway leaves an unused set directory, which the next commit removes. Files of the
//! user's own in `out/` are never touched (the scan may live there). Elsewhere than Unix, each
//! file is written atomically on its own.
use std::io::Write;
use std::path::{Path, PathBuf};

/// Why an output file could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot {doing}: {source}", path.display())]
pub struct WriteError {
    /// The destination.
    pub path: PathBuf,
    /// What could not be done: [`WRITE`], or [`CREATE_DIRECTORY`] for an output directory.
    pub doing: &'static str,
    /// What the operating system said.
    #[source]
    pub source: std::io::Error,
}

/// [`WriteError::doing`] for a file.
pub const WRITE: &str = "write";
/// [`WriteError::doing`] for an output directory that could not be made.
pub const CREATE_DIRECTORY: &str = "create the directory";

/// Writes `bytes` to `path` atomically (temporary file + rename in the same directory).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    let err = |source| WriteError { path: path.to_path_buf(), doing: WRITE, source };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new().prefix(".dressform-").tempfile_in(dir).map_err(err)?;
    tmp.write_all(bytes).map_err(err)?;
    // Temporary files are private (0600); an output is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file().set_permissions(std::fs::Permissions::from_mode(0o644)).map_err(err)?;
    }
    tmp.as_file().sync_all().map_err(err)?;
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}

/// Files that belong together, committed into a directory as a whole (see the module
/// documentation).
#[derive(Debug, Clone, Default)]
pub struct OutputSet {
    files: Vec<(String, Vec<u8>)>,
}

/// The directory in the output directory that holds the sets.
const STORE: &str = ".dressform";
/// The link, in [`STORE`], to the set in force.
const CURRENT: &str = "current";
/// The directory, in [`STORE`], of the sets.
const SETS: &str = "sets";
/// The suffix of links being put in place (left over only by a killed run).
const NEW: &str = ".dressform-new";

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        OutputSet::default()
    }

    /// Adds the file `name` (a plain file name) with `bytes`, replacing one of that name.
    pub fn add(&mut self, name: impl Into<String>, bytes: impl Into<Vec<u8>>) {
        let name = name.into();
        self.files.retain(|(n, _)| *n != name);
        self.files.push((name, bytes.into()));
    }

    /// Adds every file of `other`, replacing files of the same names.
    pub fn append(&mut self, other: OutputSet) {
        for (name, bytes) in other.files {
            self.add(name, bytes);
        }
    }

    /// The names of the files, in the order they were added.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.files.iter().map(|(n, _)| n.as_str())
    }

    /// The bytes of the file `name`, if the set has it.
    pub fn get(&self, name: &str) -> Option<&[u8]> {
        self.files.iter().find(|(n, _)| n == name).map(|(_, b)| b.as_slice())
    }

    /// Commits the set into `dir` (created if missing): after this returns, every name of the
    /// set in `dir` reads the new content; before, the old. Names of the previous set that
    /// this one lacks disappear with it. Sets left behind by killed runs are removed first.
    pub fn commit(self, dir: &Path) -> Result<(), WriteError> {
        for (name, _) in &self.files {
            let plain = Path::new(name).file_name().is_some_and(|f| f == name.as_str());
            if !plain || name.starts_with(STORE) || name.ends_with(NEW) {
                let source = std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "not a plain file name for an output",
                );
                return Err(WriteError { path: dir.join(name), doing: WRITE, source });
            }
        }
        std::fs::create_dir_all(dir).map_err(|source| WriteError {
            path: dir.into(),
            doing: CREATE_DIRECTORY,
            source,
        })?;
        #[cfg(unix)]
        return set::commit(&self.files, dir);
        #[cfg(not(unix))]
        {
            for (name, bytes) in &self.files {
                write_atomically(&dir.join(name), bytes)?;
            }
            Ok(())
        }
    }
}

#[cfg(unix)]
mod set {
    use super::{CURRENT, NEW, SETS, STORE, WriteError};
    use std::io::{ErrorKind, Write};
    use std::os::unix::fs::{PermissionsExt, symlink};
    use std::path::{Path, PathBuf};

    /// The error for `path`.
    fn at(path: &Path) -> impl FnOnce(std::io::Error) -> WriteError + '_ {
        move |source| WriteError { path: path.to_path_buf(), doing: super::WRITE, source }
    }

    pub(super) fn commit(files: &[(String, Vec<u8>)], dir: &Path) -> Result<(), WriteError> {
        let store = dir.join(STORE);
        let sets = store.join(SETS);
        std::fs::create_dir_all(&sets).map_err(at(&sets))?;
        // One commit at a time into a directory; the lock goes with the process.
        let lock_path = store.join("lock");
        let lock = std::fs::File::create(&lock_path).map_err(at(&lock_path))?;
        lock.lock().map_err(at(&lock_path))?;

        let current = store.join(CURRENT);
        let old = std::fs::read_link(&current).ok();
        remove_stale(dir, &store, old.as_deref())?;

        let staged = stage(dir, &sets, files)?;
        let staged_name = staged.file_name().map(PathBuf::from).unwrap_or_default();
        let done = link_names(dir, files)
            .and_then(|()| replace_link(&Path::new(SETS).join(&staged_name), &current))
            .and_then(|()| sync_dir(&store));
        if let Err(e) = done {
            let _ = std::fs::remove_dir_all(&staged);
            return Err(e);
        }
        // The new set is in force; what follows only tidies up.
        if let Some(old) = old.map(|o| store.join(o)) {
            let gone: Vec<String> = std::fs::read_dir(&old)
                .into_iter()
                .flatten()
                .flatten()
                .filter_map(|e| e.file_name().into_string().ok())
                .filter(|n| !files.iter().any(|(name, _)| name == n))
                .collect();
            for name in gone {
                let link = dir.join(&name);
                if std::fs::read_link(&link).is_ok_and(|t| t == target_of(&name)) {
                    std::fs::remove_file(&link).map_err(at(&link))?;
                }
            }
            std::fs::remove_dir_all(&old).map_err(at(&old))?;
        }
        sync_dir(dir)
    }

    /// Where the link `name` in the output directory points.
    fn target_of(name: &str) -> PathBuf {
        Path::new(STORE).join(CURRENT).join(name)
    }

    /// Removes what killed runs left: sets other than the one in force, and links that were
    /// being put in place.
    fn remove_stale(dir: &Path, store: &Path, current: Option<&Path>) -> Result<(), WriteError> {
        let sets = store.join(SETS);
        for entry in std::fs::read_dir(&sets).map_err(at(&sets))?.flatten() {
            let path = entry.path();
            if current.is_none_or(|c| c.file_name() != path.file_name()) {
                std::fs::remove_dir_all(&path).map_err(at(&path))?;
            }
        }
        for place in [dir, store] {
            for entry in std::fs::read_dir(place).map_err(at(place))?.flatten() {
                let leftover = entry.file_name().to_string_lossy().ends_with(NEW)
                    && entry.file_type().is_ok_and(|t| t.is_symlink());
                if leftover {
                    let path = entry.path();
                    std::fs::remove_file(&path).map_err(at(&path))?;
                }
            }
        }
        Ok(())
    }

    /// Writes the files into a new set directory and flushes them to disk; errors name the
    /// file as the user knows it (in `dir`). A failure removes the new set directory.
    fn stage(dir: &Path, sets: &Path, files: &[(String, Vec<u8>)]) -> Result<PathBuf, WriteError> {
        let staged = tempfile::Builder::new().prefix("set-").tempdir_in(sets).map_err(at(sets))?;
        std::fs::set_permissions(staged.path(), std::fs::Permissions::from_mode(0o755))
            .map_err(at(staged.path()))?;
        for (name, bytes) in files {
            let path = staged.path().join(name);
            let write = || -> std::io::Result<()> {
                let mut file = std::fs::File::create(&path)?;
                file.write_all(bytes)?;
                file.set_permissions(std::fs::Permissions::from_mode(0o644))?;
                file.sync_all()
            };
            write().map_err(at(&dir.join(name)))?;
        }
        sync_dir(staged.path())?;
        Ok(staged.keep())
    }

    /// Makes each name in `dir` a link through the current-set link. A link already in place
    /// is kept; anything else by that name (an output of an older version) is replaced.
    fn link_names(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), WriteError> {
        // Nothing is replaced unless everything can be.
        for (name, _) in files {
            let path = dir.join(name);
            if std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir()) {
                return Err(at(&path)(ErrorKind::IsADirectory.into()));
            }
        }
        for (name, _) in files {
            let path = dir.join(name);
            if std::fs::read_link(&path).is_ok_and(|t| t == target_of(name)) {
                continue;
            }
            replace_link(&target_of(name), &path)?;
        }
        sync_dir(dir)
    }

    /// Points the link `path` at `target`, atomically (a new link renamed over it).
    fn replace_link(target: &Path, path: &Path) -> Result<(), WriteError> {
        let mut fresh = path.as_os_str().to_owned();
        fresh.push(NEW);
        let fresh = PathBuf::from(fresh);
        match std::fs::remove_file(&fresh) {
            Err(e) if e.kind() != ErrorKind::NotFound => return Err(at(&fresh)(e)),
            _ => {}
        }
        symlink(target, &fresh).map_err(at(&fresh))?;
        std::fs::rename(&fresh, path).map_err(|e| {
            let _ = std::fs::remove_file(&fresh);
            at(path)(e)
        })
    }

    /// Flushes a directory's entries to disk (a rename is durable only then).
    fn sync_dir(dir: &Path) -> Result<(), WriteError> {
        std::fs::File::open(dir).and_then(|d| d.sync_all()).map_err(at(dir))
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    #[test]
    fn writes_the_whole_file_and_leaves_no_temporary_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bin");
        write_atomically(&path, b"first").unwrap();
        write_atomically(&path, b"second version").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second version");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            assert_eq!(std::fs::metadata(&path).unwrap().permissions().mode() & 0o777, 0o644);
        }
    }

    /// Every regular file under `dir`, by path relative to it, with its content.
    fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut found = Vec::new();
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let t = e.file_type().unwrap();
                if t.is_dir() {
                    stack.push(e.path());
                } else if t.is_file() {
                    let rel = e.path().strip_prefix(dir).unwrap().display().to_string();
                    found.push((rel, std::fs::read(e.path()).unwrap()));
                }
            }
        }
        found.sort();
        found
    }

    fn set(files: &[(&str, &str)]) -> OutputSet {
        let mut s = OutputSet::new();
        for (name, text) in files {
            s.add(*name, text.as_bytes());
        }
        s
    }

    #[test]
    fn a_set_replaces_the_previous_one_whole_and_leaves_other_files_alone() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("scan.ply"), "the user's scan").unwrap();
        set(&[("a.obj", "a1"), ("b.json", "b1")]).commit(&out).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a1");
        set(&[("a.obj", "a2"), ("c.json", "c2")]).commit(&out).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a2");
        assert_eq!(std::fs::read_to_string(out.join("c.json")).unwrap(), "c2");
        assert!(
            !out.join("b.json").exists() && std::fs::symlink_metadata(out.join("b.json")).is_err()
        );
        assert_eq!(std::fs::read_to_string(out.join("scan.ply")).unwrap(), "the user's scan");
        // Only the set in force is stored.
        let stored: Vec<String> =
            tree(&out).into_iter().map(|(p, _)| p).filter(|p| p.contains("sets")).collect();
        assert_eq!(stored.len(), 2, "{stored:?}");
    }

    #[test]
    fn leftovers_of_a_killed_commit_are_removed_and_older_outputs_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("a.obj"), "from an older version").unwrap();
        set(&[("a.obj", "a1")]).commit(&out).unwrap();
        // A killed run: a half-written set and a link being put in place.
        let sets = out.join(STORE).join(SETS);
        std::fs::create_dir(sets.join("set-killed")).unwrap();
        std::fs::write(sets.join("set-killed/a.obj"), "half").unwrap();
        std::os::unix::fs::symlink("x", out.join(format!("a.obj{NEW}"))).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a1");
        set(&[("a.obj", "a2")]).commit(&out).unwrap();
        let files = tree(&out);
        assert_eq!(files.len(), 2, "the set and the lock: {files:?}");
        assert!(
            std::fs::read_dir(&out)
                .unwrap()
                .flatten()
                .all(|e| !e.file_name().to_string_lossy().ends_with(NEW))
        );
    }

    #[test]
    fn a_failed_commit_keeps_the_old_set() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        set(&[("a.obj", "a1")]).commit(&out).unwrap();
        std::fs::create_dir(out.join("b.json")).unwrap(); // a directory where a file should go
        let e = set(&[("a.obj", "a2"), ("b.json", "b2")]).commit(&out).unwrap_err();
        assert!(e.to_string().contains("b.json"), "{e}");
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a1");
        let e = set(&[("../x", "no")]).commit(&out).unwrap_err();
        assert!(e.to_string().contains("not a plain file name"), "{e}");
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/out.obj");
        let e = write_atomically(&path, b"x").unwrap_err();
        assert!(e.to_string().contains("out.obj"), "{e}");
    }
}
