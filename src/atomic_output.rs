//! Writing outputs so that nothing is ever lost or mixed.
//!
//! - One file: [`write_atomically`] writes it in full to a temporary file beside its
//!   destination, flushes it to disk, then renames it over the destination. A reader sees the
//!   old file or the new one, never half of one.
//! - A set of files that belong together (`mannequin.obj`, `profiles.json`,
//!   `measurements.json`, ...): [`OutputSet`] commits them as a whole, as plain files a person
//!   can e-mail or drag into a CAD tool. A reader of the output directory sees the whole old
//!   set or the whole new set, never a mix, whenever the writer is killed or the disk fills up.
//!
//! How a set is committed into a directory `out/` (on Linux): the new folder is built beside
//! it, as `.out.dressform-XXXXXXXX`: first the list of the set's names
//! (`.dressform-outputs`), then the files, flushed; then every entry of `out/` that is not an
//! output (the user's scan and notes, a nested output folder) is linked in as a hard link — the
//! same file, not a copy, so it never disappears from `out/`. One
//! `renameat2(RENAME_EXCHANGE)` then swaps the two folders: every name switches to the new set
//! at that one instant. The old folder, now beside, is removed; anything that appeared in it
//! during the commit is moved back first. A run killed midway leaves the folder beside, which
//! the next commit into `out/` tidies up the same way (its list says which files are outputs).
//! Commits into the folders of one parent are taken one at a time (a lock on the parent).
//!
//! Where folders cannot be swapped (another OS, a filesystem without the exchange, `out/` a
//! mount point, or the working directory or one of its parents: a shell inside would be left in
//! the old folder), each file is written atomically on its own and the list last: every file
//! whole, the set not.
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

/// The file, in an output directory, that lists the names of the set in force.
const LIST: &str = ".dressform-outputs";
/// What names of dressform's own start with: the list, temporaries, the folders beside.
const OWN: &str = ".dressform";
/// Where versions before plain-file outputs kept their sets (the outputs were symbolic links
/// into it): replaced by the first commit of this version.
const OLD_STORE: &str = ".dressform";
/// The random characters in the name of a folder built beside the output directory.
const SIBLING_ID_LEN: usize = 8;

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
    /// this one lacks disappear with it. What killed runs left is tidied up first.
    pub fn commit(self, dir: &Path) -> Result<(), WriteError> {
        for (name, _) in &self.files {
            let plain = Path::new(name).file_name().is_some_and(|f| f == name.as_str());
            if !plain || name.starts_with(OWN) {
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
        // Nothing is replaced unless everything can be.
        for (name, _) in &self.files {
            let path = dir.join(name);
            if std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir()) {
                return Err(at(&path)(std::io::ErrorKind::IsADirectory.into()));
            }
        }
        let real = std::fs::canonicalize(dir).map_err(at(dir))?;
        let Some((parent, name)) = real.parent().zip(real.file_name()) else {
            return in_place(&self.files, dir);
        };
        // One commit at a time among the folders of `parent`; the lock goes with the process.
        let lock = std::fs::File::open(parent).map_err(at(parent))?;
        lock.lock().map_err(at(parent))?;
        let prefix = format!(".{}{OWN}-", name.to_string_lossy());
        for left in siblings(parent, &prefix) {
            retire(&left, &real)?;
        }
        // A shell working in `dir` (or a folder in it) would be left in the old folder by a swap.
        let working_dir = std::env::current_dir().and_then(|d| d.canonicalize()).ok();
        if !working_dir.is_some_and(|w| w.starts_with(&real))
            && let Ok(sibling) = beside(parent, &prefix, &real)
        {
            let swapped = swap(&self.files, dir, &real, &sibling);
            // `sibling` holds the old folder now, or the unused new one.
            retire(&sibling, &real)?;
            if swapped? {
                return sync_dir(parent);
            }
        }
        in_place(&self.files, dir)
    }
}

/// Builds the new folder in `sibling` and swaps it with `real` (`dir` as the user named it,
/// for messages); `false` when the two cannot be swapped here.
fn swap(
    files: &[(String, Vec<u8>)],
    dir: &Path,
    real: &Path,
    sibling: &Path,
) -> Result<bool, WriteError> {
    stage(files, dir, sibling)?;
    Ok(carry_over(files, real, sibling).and_then(|()| exchange(real, sibling)).is_ok())
}

/// The error for `path`.
fn at(path: &Path) -> impl FnOnce(std::io::Error) -> WriteError + '_ {
    move |source| WriteError { path: path.to_path_buf(), doing: WRITE, source }
}

/// The names listed in `dir`'s [`LIST`] (none when it has no list).
fn listed(dir: &Path) -> Vec<String> {
    let list = std::fs::read_to_string(dir.join(LIST)).unwrap_or_default();
    list.lines().map(str::to_string).collect()
}

/// The contents of [`LIST`] for `files`.
fn list_of(files: &[(String, Vec<u8>)]) -> String {
    files.iter().map(|(n, _)| format!("{n}\n")).collect()
}

/// Whether the entry `name` of an output directory whose list is `listed` is dressform's:
/// an output of the set in force or of an older version, the list, a temporary.
fn is_output(dir: &Path, name: &str, listed: &[String]) -> bool {
    let older_version = std::fs::read_link(dir.join(name)).is_ok_and(|t| t.starts_with(OLD_STORE));
    name.starts_with(OWN) || listed.iter().any(|n| n == name) || older_version
}

/// Writes the files one by one, each atomically, then the list; removes the names of the
/// previous set that this one lacks.
fn in_place(files: &[(String, Vec<u8>)], dir: &Path) -> Result<(), WriteError> {
    let previous = listed(dir);
    for (name, bytes) in files {
        write_atomically(&dir.join(name), bytes)?;
    }
    write_atomically(&dir.join(LIST), list_of(files).as_bytes())?;
    for name in previous.iter().filter(|p| !files.iter().any(|(n, _)| n == *p)) {
        let path = dir.join(name);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(at(&path)(e)),
            _ => {}
        }
    }
    let old_store = dir.join(OLD_STORE);
    if old_store.is_dir() {
        std::fs::remove_dir_all(&old_store).map_err(at(&old_store))?;
    }
    Ok(())
}

/// The folders beside `dir` in `parent` named `prefix` + an id: left by killed commits.
fn siblings(parent: &Path, prefix: &str) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(parent) else { return Vec::new() };
    entries
        .flatten()
        .filter(|e| {
            let name = e.file_name();
            let id = name.to_str().and_then(|n| n.strip_prefix(prefix)).unwrap_or_default();
            id.len() == SIBLING_ID_LEN && id.chars().all(|c| c.is_ascii_alphanumeric())
        })
        .map(|e| e.path())
        .collect()
}

/// A new empty folder beside `dir`, with `dir`'s permissions.
fn beside(parent: &Path, prefix: &str, dir: &Path) -> std::io::Result<PathBuf> {
    let made =
        tempfile::Builder::new().prefix(prefix).rand_bytes(SIBLING_ID_LEN).tempdir_in(parent)?;
    std::fs::set_permissions(made.path(), std::fs::metadata(dir)?.permissions())?;
    Ok(made.keep())
}

/// Writes the list, then the files, into `sibling` and flushes them; errors name the file as
/// the user knows it (in `dir`).
fn stage(files: &[(String, Vec<u8>)], dir: &Path, sibling: &Path) -> Result<(), WriteError> {
    let list = list_of(files);
    let all = std::iter::once((LIST, list.as_bytes()))
        .chain(files.iter().map(|(n, b)| (n.as_str(), b.as_slice())));
    for (name, bytes) in all {
        let write = || -> std::io::Result<()> {
            let mut file = std::fs::File::create(sibling.join(name))?;
            file.write_all(bytes)?;
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                file.set_permissions(std::fs::Permissions::from_mode(0o644))?;
            }
            file.sync_all()
        };
        write().map_err(at(&dir.join(name)))?;
    }
    Ok(())
}

/// Links every entry of `dir` that is not an output (of the old set or the new) into
/// `sibling`: files as hard links, folders as new folders of links, symbolic links anew.
fn carry_over(files: &[(String, Vec<u8>)], dir: &Path, sibling: &Path) -> std::io::Result<()> {
    let previous = listed(dir);
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        let name_str = name.to_string_lossy();
        let new_output = files.iter().any(|(n, _)| *n == name_str);
        if new_output || is_output(dir, &name_str, &previous) {
            continue;
        }
        link_tree(&entry.path(), &sibling.join(&name))?;
    }
    sync_dir(sibling).map_err(|e| e.source)
}

/// `to` made the same as `from`: hard links for files, recursively for folders.
fn link_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    let meta = std::fs::symlink_metadata(from)?;
    if meta.is_dir() {
        std::fs::create_dir(to)?;
        std::fs::set_permissions(to, meta.permissions())?;
        for entry in std::fs::read_dir(from)? {
            let entry = entry?;
            link_tree(&entry.path(), &to.join(entry.file_name()))?;
        }
        Ok(())
    } else if meta.is_symlink() {
        symlink(&std::fs::read_link(from)?, to)
    } else {
        std::fs::hard_link(from, to)
    }
}

#[cfg(unix)]
use std::os::unix::fs::symlink;
#[cfg(not(unix))]
fn symlink(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

/// Swaps the folders `a` and `b` in one step.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c =
        |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::from);
    let (a, b) = (c(a)?, c(b)?);
    // SAFETY: both paths are NUL-terminated strings that outlive the call; AT_FDCWD makes
    // them relative to the working directory (they are absolute here).
    let done = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if done == 0 { Ok(()) } else { Err(std::io::Error::last_os_error()) }
}

/// Folders cannot be swapped in one step here.
#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

/// Removes a folder beside `dir` (the old folder after a swap, or one a killed commit left):
/// its outputs (by its own list), files the set in `dir` replaced (by `dir`'s list), and
/// whatever `dir` holds too (the same hard link, or the same symbolic link); anything else is
/// the user's and moves into `dir` when the name is free there. A folder that still holds
/// something is kept, never deleted with it.
fn retire(sibling: &Path, dir: &Path) -> Result<(), WriteError> {
    let (outputs, replaced) = (listed(sibling), listed(dir));
    let ours =
        |name: &str| is_output(sibling, name, &outputs) || replaced.iter().any(|n| n == name);
    merge_into(sibling, dir, &ours)?;
    sync_dir(dir)
}

/// [`retire`] for one folder level; `ours` tells dressform's entries at this level.
fn merge_into(from: &Path, to: &Path, ours: &dyn Fn(&str) -> bool) -> Result<(), WriteError> {
    use std::io::ErrorKind::NotFound;
    for entry in std::fs::read_dir(from).map_err(at(from))?.flatten() {
        let (path, name) = (entry.path(), entry.file_name());
        let there = to.join(&name);
        let meta = std::fs::symlink_metadata(&path).map_err(at(&path))?;
        if ours(&name.to_string_lossy()) {
            remove(&path, &meta)?;
            continue;
        }
        match std::fs::symlink_metadata(&there) {
            Err(e) if e.kind() == NotFound => std::fs::rename(&path, &there).map_err(at(&there))?,
            Err(e) => return Err(at(&there)(e)),
            Ok(m) if m.is_dir() && meta.is_dir() => {
                merge_into(&path, &there, &|_| false)?;
            }
            Ok(m) if same(&m, &meta) || (m.is_symlink() && same_link(&path, &there)) => {
                remove(&path, &meta)?;
            }
            Ok(_) => {} // the user's, changed in both places: kept beside
        }
    }
    match std::fs::remove_dir(from) {
        Err(e) if e.kind() != std::io::ErrorKind::DirectoryNotEmpty => Err(at(from)(e)),
        _ => Ok(()),
    }
}

/// Removes a file, link or folder.
fn remove(path: &Path, meta: &std::fs::Metadata) -> Result<(), WriteError> {
    let removed =
        if meta.is_dir() { std::fs::remove_dir_all(path) } else { std::fs::remove_file(path) };
    removed.map_err(at(path))
}

/// Whether two entries are the same file (hard links of one another).
#[cfg(unix)]
fn same(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    !a.is_dir() && (a.dev(), a.ino()) == (b.dev(), b.ino())
}

/// Whether two entries are the same file: not known here.
#[cfg(not(unix))]
fn same(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    false
}

/// Whether two symbolic links point at the same place.
fn same_link(a: &Path, b: &Path) -> bool {
    matches!((std::fs::read_link(a), std::fs::read_link(b)), (Ok(x), Ok(y)) if x == y)
}

/// Flushes a directory's entries to disk (a rename is durable only then).
fn sync_dir(dir: &Path) -> Result<(), WriteError> {
    #[cfg(unix)]
    return std::fs::File::open(dir).and_then(|d| d.sync_all()).map_err(at(dir));
    #[cfg(not(unix))]
    Ok(())
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

    /// The entries of `parent` beside `out` (folders of commits).
    fn beside_out(parent: &Path) -> Vec<String> {
        let names = std::fs::read_dir(parent).unwrap().flatten();
        names.map(|e| e.file_name().into_string().unwrap()).filter(|n| n != "out").collect()
    }

    #[test]
    fn a_set_replaces_the_previous_one_whole_and_leaves_other_files_alone() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("notes")).unwrap();
        std::fs::write(out.join("scan.ply"), "the user's scan").unwrap();
        std::fs::write(out.join("notes/fit.txt"), "a note").unwrap();
        set(&[("a.obj", "a1"), ("b.json", "b1")]).commit(&out).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a1");
        let held = std::fs::File::open(out.join("scan.ply")).unwrap();
        set(&[("a.obj", "a2"), ("c.json", "c2")]).commit(&out).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a2");
        assert_eq!(std::fs::read_to_string(out.join("c.json")).unwrap(), "c2");
        assert!(std::fs::symlink_metadata(out.join("b.json")).is_err());
        // The user's files: the same files (not copies), in place.
        use std::os::unix::fs::MetadataExt;
        let (was, is) =
            (held.metadata().unwrap(), std::fs::metadata(out.join("scan.ply")).unwrap());
        assert_eq!((was.ino(), was.nlink()), (is.ino(), 1));
        assert_eq!(std::fs::read_to_string(out.join("notes/fit.txt")).unwrap(), "a note");
        // Plain files only, and nothing left beside.
        let files = tree(&out);
        let names: Vec<&str> = files.iter().map(|(p, _)| p.as_str()).collect();
        assert_eq!(names, [LIST, "a.obj", "c.json", "notes/fit.txt", "scan.ply"]);
        assert!(beside_out(dir.path()).is_empty(), "{:?}", beside_out(dir.path()));
    }

    #[test]
    fn leftovers_of_killed_commits_are_tidied_and_older_outputs_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("a.obj"), "from an older version").unwrap();
        std::fs::write(out.join("scan.ply"), "the user's scan").unwrap();
        set(&[("a.obj", "a1")]).commit(&out).unwrap();
        // Killed before the swap: a new folder half built (its list, a file, the scan linked).
        let before = dir.path().join(".out.dressform-killed01");
        std::fs::create_dir(&before).unwrap();
        std::fs::write(before.join(LIST), "a.obj\nb.json\n").unwrap();
        std::fs::write(before.join("a.obj"), "half").unwrap();
        std::fs::hard_link(out.join("scan.ply"), before.join("scan.ply")).unwrap();
        // Killed after a swap: the old folder, with a note the user wrote meanwhile.
        let after = dir.path().join(".out.dressform-killed02");
        std::fs::create_dir(&after).unwrap();
        std::fs::write(after.join(LIST), "a.obj\n").unwrap();
        std::fs::write(after.join("a.obj"), "a0").unwrap();
        std::fs::write(after.join("note.txt"), "written during the swap").unwrap();
        // An older version's output: a symbolic link into its store.
        std::fs::create_dir_all(out.join(".dressform/current")).unwrap();
        std::fs::write(out.join(".dressform/current/old.json"), "old").unwrap();
        symlink(Path::new(".dressform/current/old.json"), out.join("old.json")).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.obj")).unwrap(), "a1");

        set(&[("a.obj", "a2")]).commit(&out).unwrap();
        let files = tree(&out);
        let names: Vec<&str> = files.iter().map(|(p, _)| p.as_str()).collect();
        assert_eq!(names, [LIST, "a.obj", "note.txt", "scan.ply"]);
        assert!(std::fs::symlink_metadata(out.join("old.json")).is_err());
        assert!(beside_out(dir.path()).is_empty(), "{:?}", beside_out(dir.path()));
    }

    #[test]
    fn the_working_directory_is_written_in_place() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        set(&[("a.obj", "a1"), ("b.json", "b1")]).commit(&out).unwrap();
        let before = std::fs::metadata(&out).unwrap();
        // In place: the directory stays the same one (a shell inside it keeps seeing it).
        in_place(&[("a.obj".into(), b"a2".to_vec())], &out).unwrap();
        use std::os::unix::fs::MetadataExt;
        assert_eq!(std::fs::metadata(&out).unwrap().ino(), before.ino());
        let files = tree(&out);
        assert_eq!(
            files,
            [(LIST.to_string(), b"a.obj\n".to_vec()), ("a.obj".into(), b"a2".to_vec())]
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
