//! A set of files written together ([`Outputs`]): a run's set replaces the directory's previous
//! set as a whole, and nothing that the program did not write is removed or changed.
//!
//! # The layout (Unix)
//!
//! ```text
//! DIR/run.json      -> .piezocontact/current/run.json    (one link per file of the set)
//! DIR/contact.csv   -> .piezocontact/current/contact.csv
//! DIR/notes.txt                                           (the user's: never touched)
//! DIR/.piezocontact/current -> set-4711-1733140000123456789
//! DIR/.piezocontact/set-4711-1733140000123456789/run.json ...
//! DIR/.piezocontact/README, lock
//! ```
//!
//! A commit writes the new set into a fresh directory under `.piezocontact/`, makes the links
//! its files need, then turns the one link `current` to it by a rename (atomic), then removes
//! the links of the files the new set lacks and the old set's directory. A reader sees the old
//! set or the new one at every instant: a link whose file the current set lacks is an absent
//! file. `DIR` itself is never renamed, so `--out` may be `.`, `..`, a mount point, a link to a
//! directory (written through, into its target) or a directory full of the user's files; a
//! name of the set that the directory holds as a file of the user's (not one of our links)
//! stops the commit before anything is written. Commits into one directory are serialised by a
//! lock; what a killed commit left is removed by the next.
//!
//! A directory written by an earlier version (regular files listed in `.piezocontact-outputs`)
//! is taken over without a visible step: its files are hard-linked into a set of their own,
//! which becomes `current`, and each file is then replaced by its link to the same content.
//!
//! Documents ([`Outputs::documents`]: the pages the studies write into `docs/`) are files kept
//! in a source tree: each is replaced in place, atomically by itself (written beside it, then
//! renamed over it), and nothing else in the directory is touched.

use crate::Error;
use std::path::{Path, PathBuf};

/// The hidden directory of a set, inside the output directory.
const HIDDEN: &str = ".piezocontact";
/// The link in [`HIDDEN`] to the current set.
const CURRENT: &str = "current";
/// The file in [`HIDDEN`] that says what the directory is (and that it is ours).
const README: &str = "README";
/// The lock file in [`HIDDEN`].
const LOCK: &str = "lock";
/// The manifest of the sets of earlier versions (regular files in the directory itself).
const LEGACY_MANIFEST: &str = ".piezocontact-outputs";

const README_TEXT: &str = "This directory holds the output sets of piezocontact runs. `current` is a link to the\n\
set of the last run; the files of the directory above are links into it, so that a new set\n\
replaces the old one as a whole. Copy the directory above with its links (cp -r, tar) or\n\
with their files (cp -rL); do not edit this directory by hand.\n";

/// How the files are put in place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// A run's output set, replaced as a whole.
    Set,
    /// Documents in a source tree, each replaced by itself.
    Documents,
}

/// Files to write together: a run's output set, or documents.
pub struct Outputs {
    dir: PathBuf,
    files: Vec<(String, Vec<u8>)>,
    mode: Mode,
}

impl Outputs {
    /// A run's output set for directory `dir` (made on commit), replacing its previous set.
    pub fn new(dir: &Path) -> Self {
        Outputs {
            dir: dir.to_path_buf(),
            files: vec![],
            mode: Mode::Set,
        }
    }

    /// Documents for directory `dir` (a source tree's `docs/`): each file replaced in place by
    /// itself, as plain files.
    pub fn documents(dir: &Path) -> Self {
        Outputs {
            mode: Mode::Documents,
            ..Self::new(dir)
        }
    }

    /// The same files, for directory `dir`.
    pub fn into(self, dir: &Path) -> Self {
        Outputs {
            dir: dir.to_path_buf(),
            ..self
        }
    }

    /// Adds a file's bytes.
    pub fn add(&mut self, name: &str, bytes: Vec<u8>) {
        self.files.push((name.to_string(), bytes));
    }

    /// Adds several files.
    pub fn extend(&mut self, files: crate::plots::Files) {
        self.files.extend(files);
    }

    /// The files, in the order they were added.
    pub fn into_files(self) -> Vec<(String, Vec<u8>)> {
        self.files
    }

    /// The names of the files, in the order they were added.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.files.iter().map(|(n, _)| n.as_str())
    }

    /// Writes the files: a set replaces the directory's previous set as a whole (see the
    /// module's documentation), documents replace their namesakes one by one.
    ///
    /// # Errors
    /// [`Error::OutputConflict`] where a name is not a plain file name, or names a file
    /// of the user's; [`Error::Output`] naming the path that could not be created,
    /// written or renamed. Nothing is changed where the error comes before the set is turned
    /// to (every error but a failure to remove what the old set leaves).
    pub fn commit(self) -> Result<(), Error> {
        let mut seen = std::collections::BTreeSet::new();
        for (name, _) in &self.files {
            check_name(&self.dir, name)?;
            if !seen.insert(name.as_str()) {
                return Err(conflict(
                    &self.dir.join(name),
                    "is twice in the set: two files would write one name",
                ));
            }
        }
        match self.mode {
            Mode::Documents => self.commit_documents(),
            Mode::Set => self.commit_set(),
        }
    }

    fn commit_documents(self) -> Result<(), Error> {
        std::fs::create_dir_all(&self.dir).map_err(|e| io("cannot create", &self.dir, e))?;
        for (name, bytes) in &self.files {
            let path = self.dir.join(name);
            let tmp = self.dir.join(format!(".{name}.piezocontact-{}", std::process::id()));
            std::fs::write(&tmp, bytes)
                .and_then(|()| std::fs::rename(&tmp, &path))
                .map_err(|e| {
                    let _ = std::fs::remove_file(&tmp);
                    io("cannot write", &path, e)
                })?;
        }
        // the manifest earlier versions left among the documents
        let _ = std::fs::remove_file(self.dir.join(LEGACY_MANIFEST));
        Ok(())
    }

    #[cfg(not(unix))]
    fn commit_set(self) -> Result<(), Error> {
        // without links, each file is replaced by itself
        Outputs {
            mode: Mode::Documents,
            ..self
        }
        .commit_documents()
    }

    #[cfg(unix)]
    fn commit_set(self) -> Result<(), Error> {
        check_dir(&self.dir)?;
        unix::commit(&self.dir, &self.files)
    }
}

/// Whether a run's outputs can go to `dir`, asked before the run (which may take hours) rather
/// than at its end: `dir` is a directory or nothing yet (not a link to nothing), and the nearest of it
/// and its ancestors that exists is a directory in which a directory can be made (one is made
/// and removed: a read-only or special file system refuses it). Nothing is left behind.
///
/// # Errors
/// [`Error::OutputConflict`] where `dir` or an ancestor is a file; [`Error::Output`] where no
/// directory can be made there.
pub fn check_target(dir: &Path) -> Result<(), Error> {
    let absolute = std::path::absolute(dir).map_err(|e| io("cannot resolve", dir, e))?;
    let Some(existing) = absolute.ancestors().find(|a| std::fs::symlink_metadata(a).is_ok()) else {
        return Ok(());
    };
    if existing != absolute && !existing.is_dir() {
        return Err(conflict(existing, "is not a directory (it is on the way to --out)"));
    }
    check_dir(dir)?;
    let probe = existing.join(format!(".piezocontact-probe-{}", std::process::id()));
    std::fs::create_dir(&probe).map_err(|e| io("cannot create", &absolute.join(".piezocontact"), e))?;
    std::fs::remove_dir(&probe).map_err(|e| io("cannot remove", &probe, e))
}

/// An output directory: a directory, or nothing yet (a link to nothing is refused).
fn check_dir(dir: &Path) -> Result<(), Error> {
    match std::fs::metadata(dir) {
        Ok(m) if !m.is_dir() => Err(conflict(dir, "is not a directory")),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            // a link whose target is absent; not a directory another run made meanwhile (it
            // was absent a moment ago: commits into one new directory race to make it)
            match std::fs::symlink_metadata(dir) {
                Ok(l) if l.file_type().is_symlink() && std::fs::metadata(dir).is_err() => Err(conflict(
                    dir,
                    "is a link to nothing: make its target, or give another --out",
                )),
                _ => Ok(()),
            }
        }
        Err(e) => Err(io("cannot read", dir, e)),
    }
}

/// A run's output set written file by file as the run makes them (the steps of a load path,
/// each written and dropped, not held), then turned to as a whole by [`SetWriter::finish`]:
/// the same set as [`Outputs::commit`] makes, with what is not finished removed.
pub struct SetWriter {
    #[cfg(unix)]
    inner: unix::Writer,
    #[cfg(not(unix))]
    out: Outputs,
    dir: PathBuf,
}

impl SetWriter {
    /// Begins a set in `dir`. `names` known in advance are checked first: a name that is not a
    /// plain file name, or a file of the user's, stops it before anything is written.
    ///
    /// # Errors
    /// As [`Outputs::commit`].
    pub fn begin(dir: &Path, names: &[String]) -> Result<Self, Error> {
        for name in names {
            check_name(dir, name)?;
        }
        check_dir(dir)?;
        Ok(SetWriter {
            #[cfg(unix)]
            inner: unix::Writer::begin(dir, names)?,
            #[cfg(not(unix))]
            out: Outputs::new(dir),
            dir: dir.to_path_buf(),
        })
    }

    /// Writes one file of the set (visible once the set is finished).
    ///
    /// # Errors
    /// As [`Outputs::commit`].
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), Error> {
        check_name(&self.dir, name)?;
        #[cfg(unix)]
        return self.inner.write(name, bytes);
        #[cfg(not(unix))]
        {
            self.out.add(name, bytes.to_vec());
            Ok(())
        }
    }

    /// Writes every file of `outputs`.
    ///
    /// # Errors
    /// As [`SetWriter::write`].
    pub fn write_all(&mut self, outputs: Outputs) -> Result<(), Error> {
        for (name, bytes) in outputs.files {
            self.write(&name, &bytes)?;
        }
        Ok(())
    }

    /// The directory the set's files are written into before the set is turned to, where
    /// another process may write files of the set ([`super::pieces::write_into`]; the ranks of
    /// a parallel run) for [`SetWriter::adopt`] to take in; `None` where the platform stages
    /// files in memory.
    pub fn staging(&self) -> Option<&Path> {
        #[cfg(unix)]
        return Some(&self.inner.set);
        #[cfg(not(unix))]
        None
    }

    /// A handle through which other threads write files of the set ([`Staged::write`]) for
    /// [`SetWriter::adopt`] to take in (a load path's steps, each written by the thread that
    /// encoded it while the path goes on); `None` where the platform stages files in memory.
    pub fn staged(&self) -> Option<Staged> {
        #[cfg(unix)]
        return Some(Staged {
            set: self.inner.set.clone(),
            dir: self.dir.clone(),
        });
        #[cfg(not(unix))]
        None
    }

    /// Takes into the set the file `name` that another process wrote into
    /// [`SetWriter::staging`].
    ///
    /// # Errors
    /// As [`SetWriter::write`]; [`Error::Output`] where the file is not there.
    pub fn adopt(&mut self, name: &str) -> Result<(), Error> {
        check_name(&self.dir, name)?;
        #[cfg(unix)]
        return self.inner.adopt(name);
        #[cfg(not(unix))]
        Err(Error::Output {
            what: format!("cannot adopt {name}: files are staged in memory on this platform"),
            source: std::io::Error::from(std::io::ErrorKind::Unsupported),
        })
    }

    /// Turns the directory to the set.
    ///
    /// # Errors
    /// As [`Outputs::commit`].
    pub fn finish(self) -> Result<(), Error> {
        #[cfg(unix)]
        return self.inner.finish();
        #[cfg(not(unix))]
        self.out.commit()
    }
}

/// A set's staging directory, written into from any thread ([`SetWriter::staged`]).
#[derive(Clone, Debug)]
pub struct Staged {
    set: PathBuf,
    dir: PathBuf,
}

impl Staged {
    /// Writes one file of the set into its staging directory, its bytes given by `write`,
    /// under the registry's lock as [`SetWriter::write`] writes (a signal's removal of the set
    /// waits for it; a set already removed is not written into). The file is the set's once
    /// [`SetWriter::adopt`] takes it (which checks its name against the user's files).
    ///
    /// # Errors
    /// As [`SetWriter::write`]; [`Error::Output`] where the set was abandoned.
    pub fn write(
        &self,
        name: &str,
        write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
    ) -> Result<(), Error> {
        check_name(&self.dir, name)?;
        let sets = staging();
        if !sets.contains(&self.set) {
            return Err(Error::Output {
                what: format!(
                    "cannot write {}: the set being written was abandoned",
                    self.dir.join(name).display()
                ),
                source: std::io::Error::from(std::io::ErrorKind::NotFound),
            });
        }
        let written = std::fs::File::create(self.set.join(name)).and_then(|file| {
            // pieces as large as the buffer go to the file without a copy
            let mut w = std::io::BufWriter::with_capacity(1 << 15, file);
            write(&mut w)?;
            w.into_inner().map(drop).map_err(std::io::IntoInnerError::into_error)
        });
        written.map_err(|e| io("cannot write", &self.dir.join(name), e))
    }
}

/// A set's file name: one plain component, not hidden, not ours.
fn check_name(dir: &Path, name: &str) -> Result<(), Error> {
    let mut parts = Path::new(name).components();
    let plain = matches!(parts.next(), Some(std::path::Component::Normal(_))) && parts.next().is_none();
    if !plain || name.starts_with('.') || name.contains('/') {
        return Err(conflict(
            &dir.join(name),
            "is not a plain file name (one component, not hidden)",
        ));
    }
    Ok(())
}

fn io(what: &str, p: &Path, e: std::io::Error) -> Error {
    // EFBIG: a write past the file-size limit (the driver ignores SIGXFSZ, so it fails here)
    let limit = if e.kind() == std::io::ErrorKind::FileTooLarge {
        " (the file-size limit, ulimit -f, is smaller than the file: raise it, or write fewer or smaller files, e.g. path.output_every)"
    } else {
        ""
    };
    Error::Output {
        what: format!("{what} {}{limit}", p.display()),
        source: e,
    }
}

/// The sets being written in this process (their directories under `.piezocontact/`), so that
/// a run stopped by a signal removes them on its way out.
static STAGING: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn staging() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    STAGING.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Removes the sets this process was writing and ends it with `code`, the registry held to
/// the end so that no set is begun after it (the driver calls it on SIGINT, SIGTERM, SIGHUP: a
/// stopped run leaves no partial set behind, and the previous set stays the directory's).
pub fn abandon_and_exit(code: i32) -> ! {
    let mut sets = staging();
    for set in sets.drain(..) {
        let _ = std::fs::remove_dir_all(set);
    }
    std::process::exit(code)
}

fn conflict(p: &Path, why: &str) -> Error {
    Error::OutputConflict {
        path: p.display().to_string(),
        reason: why.into(),
    }
}

#[cfg(unix)]
mod unix {
    use super::{conflict, io, staging, CURRENT, HIDDEN, LEGACY_MANIFEST, LOCK, README, README_TEXT};
    use crate::Error;
    use std::os::unix::fs::symlink;
    use std::path::{Path, PathBuf};

    /// The link of file `name`, as it reads from the output directory.
    fn link_target(name: &str) -> PathBuf {
        Path::new(HIDDEN).join(CURRENT).join(name)
    }

    /// Whether `path` is the link of file `name`.
    fn is_our_link(path: &Path, name: &str) -> bool {
        std::fs::read_link(path).is_ok_and(|t| t == link_target(name))
    }

    /// The names of the files of the set `current` points to (empty without one).
    fn current_names(hidden: &Path) -> Vec<String> {
        std::fs::read_dir(hidden.join(CURRENT))
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect()
    }

    /// The regular files of an earlier version's set, by its manifest.
    fn legacy_names(dir: &Path) -> Vec<String> {
        std::fs::read_to_string(dir.join(LEGACY_MANIFEST))
            .map(|t| {
                t.lines()
                    .filter(|l| !l.is_empty() && !l.contains('/'))
                    .filter(|l| std::fs::symlink_metadata(dir.join(l)).is_ok_and(|m| m.is_file()))
                    .map(String::from)
                    .collect()
            })
            .unwrap_or_default()
    }

    /// Whether an entry of the hidden directory is one this module makes.
    fn ours(name: &str) -> bool {
        [CURRENT, README, LOCK].contains(&name) || ["set-", "turning-"].iter().any(|p| name.starts_with(p))
    }

    /// The hidden directory, made where missing (by this commit or one beside it); refused
    /// where something else has its name.
    fn hidden_dir(dir: &Path) -> Result<PathBuf, Error> {
        let hidden = dir.join(HIDDEN);
        let foreign = || {
            conflict(
                &hidden,
                "is not piezocontact's (it holds what no run made): move it, or choose another --out; nothing was written",
            )
        };
        match std::fs::symlink_metadata(&hidden) {
            Ok(m) if !m.is_dir() => return Err(foreign()),
            Ok(_) if hidden.join(README).is_file() => return Ok(hidden),
            Ok(_) => {
                let all_ours = std::fs::read_dir(&hidden)
                    .map_err(|e| io("cannot read", &hidden, e))?
                    .flatten()
                    .all(|e| ours(&e.file_name().to_string_lossy()));
                if !all_ours {
                    return Err(foreign());
                }
            }
            Err(_) => std::fs::create_dir_all(&hidden).map_err(|e| io("cannot create", &hidden, e))?,
        }
        Ok(hidden)
    }

    /// The hidden directory's README, written where missing; under the lock, since another
    /// commit's clean-up ([`remove_stale`]) removes the temporary names it does not own.
    fn write_readme(hidden: &Path) -> Result<(), Error> {
        if hidden.join(README).is_file() {
            return Ok(());
        }
        let tmp = fresh(hidden, "turning");
        std::fs::write(&tmp, README_TEXT)
            .and_then(|()| std::fs::rename(&tmp, hidden.join(README)))
            .map_err(|e| io("cannot write", &hidden.join(README), e))
    }

    /// A fresh name in `hidden`: the process, the time and a count of this process's names.
    fn fresh(hidden: &Path, what: &str) -> PathBuf {
        static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let k = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        hidden.join(format!("{what}-{}-{nanos}-{k}", std::process::id()))
    }

    /// Turns `current` to `set` (a name in `hidden`): one rename.
    fn turn(hidden: &Path, set: &Path) -> Result<(), Error> {
        let name = set.file_name().unwrap_or_default();
        let tmp = fresh(hidden, "turning");
        symlink(name, &tmp).map_err(|e| io("cannot link", &tmp, e))?;
        std::fs::rename(&tmp, hidden.join(CURRENT)).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            io("cannot turn", &hidden.join(CURRENT), e)
        })
    }

    /// The set directories, and stray links, that `current` does not point to (a killed
    /// commit's).
    fn remove_stale(hidden: &Path) {
        let live = std::fs::read_link(hidden.join(CURRENT)).ok();
        for entry in std::fs::read_dir(hidden).into_iter().flatten().flatten() {
            let name = entry.file_name();
            let keep = [CURRENT, README, LOCK].iter().any(|k| name == *k)
                || live.as_deref() == Some(Path::new(&name))
                || !ours(&name.to_string_lossy());
            if !keep {
                let _ = std::fs::remove_dir_all(entry.path()).or_else(|_| std::fs::remove_file(entry.path()));
            }
        }
    }

    /// Takes over the set an earlier version wrote as regular files: hard-linked into a set of
    /// its own that becomes `current`, then each file replaced by its link (the same content).
    fn adopt_legacy(dir: &Path, hidden: &Path) -> Result<(), Error> {
        let names = legacy_names(dir);
        if names.is_empty() {
            let _ = std::fs::remove_file(dir.join(LEGACY_MANIFEST));
            return Ok(());
        }
        let set = fresh(hidden, "set");
        std::fs::create_dir(&set).map_err(|e| io("cannot create", &set, e))?;
        for name in &names {
            std::fs::hard_link(dir.join(name), set.join(name)).map_err(|e| io("cannot link", &dir.join(name), e))?;
        }
        turn(hidden, &set)?;
        for name in &names {
            let tmp = dir.join(format!(".{name}.piezocontact-link"));
            let _ = std::fs::remove_file(&tmp);
            symlink(link_target(name), &tmp)
                .and_then(|()| std::fs::rename(&tmp, dir.join(name)))
                .map_err(|e| io("cannot link", &dir.join(name), e))?;
        }
        let _ = std::fs::remove_file(dir.join(LEGACY_MANIFEST));
        Ok(())
    }

    /// Whether `name` in `dir` is free for a set: absent, our link, or an earlier version's
    /// file (`legacy`); else the error that stops the writing.
    fn check_free(dir: &Path, name: &str, legacy: &[String]) -> Result<(), Error> {
        let path = dir.join(name);
        let free = match std::fs::symlink_metadata(&path) {
            Err(_) => true,
            Ok(_) => is_our_link(&path, name) || legacy.iter().any(|l| l == name),
        };
        if free {
            Ok(())
        } else {
            Err(conflict(
                &path,
                "is not a file of an earlier run (it is yours, or another program's): move or rename it, or choose another --out; nothing was written",
            ))
        }
    }

    /// A set being written into `dir`, file by file, under the directory's lock: the files
    /// go into a fresh set directory beside the current one, and [`Writer::finish`] turns to
    /// it. Dropped unfinished, it removes what it made.
    pub(super) struct Writer {
        dir: PathBuf,
        hidden: PathBuf,
        pub(super) set: PathBuf,
        legacy: Vec<String>,
        names: Vec<String>,
        /// What the writer made that was not there: the directory itself, its hidden one.
        made: (bool, bool),
        _lock: std::fs::File,
        done: bool,
    }

    impl Writer {
        /// Begins a set in `dir`; `names` known in advance are checked before anything is
        /// made (a name that is the user's stops the writing there).
        pub(super) fn begin(dir: &Path, names: &[String]) -> Result<Writer, Error> {
            let legacy = legacy_names(dir);
            for name in names {
                check_free(dir, name, &legacy)?;
            }
            let made = (!dir.exists(), !dir.join(HIDDEN).exists());
            let undo = |e: Error| {
                unmake(dir, made);
                e
            };
            let hidden = hidden_dir(dir).map_err(undo)?;
            let lock =
                std::fs::File::create(hidden.join(LOCK)).map_err(|e| undo(io("cannot open", &hidden.join(LOCK), e)))?;
            lock.lock()
                .map_err(|e| undo(io("cannot lock", &hidden.join(LOCK), e)))?;
            remove_stale(&hidden);
            write_readme(&hidden).map_err(undo)?;
            adopt_legacy(dir, &hidden).map_err(undo)?;
            let set = fresh(&hidden, "set");
            {
                // registered before it exists, under the registry's lock (see abandon_and_exit)
                let mut sets = staging();
                sets.push(set.clone());
                std::fs::create_dir(&set).map_err(|e| {
                    sets.retain(|s| s != &set);
                    undo(io("cannot create", &set, e))
                })?;
            }
            Ok(Writer {
                dir: dir.to_path_buf(),
                hidden,
                set,
                legacy,
                names: vec![],
                made,
                _lock: lock,
                done: false,
            })
        }

        /// Writes one file of the set (not yet visible).
        pub(super) fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), Error> {
            check_free(&self.dir, name, &self.legacy)?;
            if self.names.iter().any(|n| n == name) {
                return Err(conflict(
                    &self.dir.join(name),
                    "is twice in the set: two files would write one name",
                ));
            }
            // held while the file is written: a signal's removal of the set waits for it, and
            // no file is written into the set after it (a file made while the set's directory
            // was being removed would leave it behind)
            let _writing = staging();
            std::fs::write(self.set.join(name), bytes).map_err(|e| io("cannot write", &self.dir.join(name), e))?;
            self.names.push(name.to_string());
            Ok(())
        }

        /// Takes in the file `name` another process wrote into the set's directory.
        pub(super) fn adopt(&mut self, name: &str) -> Result<(), Error> {
            check_free(&self.dir, name, &self.legacy)?;
            if self.names.iter().any(|n| n == name) {
                return Err(conflict(
                    &self.dir.join(name),
                    "is twice in the set: two files would write one name",
                ));
            }
            let path = self.set.join(name);
            std::fs::metadata(&path).map_err(|e| io("cannot find the file written for the set", &path, e))?;
            self.names.push(name.to_string());
            Ok(())
        }

        /// Makes the set the directory's: the links its files need, the turn of `current`
        /// to it, then the links and files of the old set that it lacks removed.
        pub(super) fn finish(mut self) -> Result<(), Error> {
            let (dir, hidden) = (&self.dir, &self.hidden);
            let old = current_names(hidden);
            let old_set = std::fs::read_link(hidden.join(CURRENT)).ok().map(|t| hidden.join(t));
            // held while the directory turns to the set: a signal then either removes the set
            // before the turn or finds it the directory's own (no longer staged)
            let mut sets = staging();
            let staged = (|| -> Result<(), Error> {
                // the links the new set's files need (each an absent file until the turn)
                for name in &self.names {
                    let path = dir.join(name);
                    if !is_our_link(&path, name) {
                        symlink(link_target(name), &path).map_err(|e| io("cannot link", &path, e))?;
                    }
                }
                turn(hidden, &self.set)
            })();
            if let Err(e) = staged {
                for name in self.names.iter().filter(|n| !old.contains(n)) {
                    let path = dir.join(name);
                    if is_our_link(&path, name) {
                        let _ = std::fs::remove_file(&path);
                    }
                }
                return Err(e);
            }
            sets.retain(|s| s != &self.set);
            drop(sets);
            self.done = true;
            // what the old set had and the new one lacks
            for name in old.iter().filter(|n| !self.names.contains(n)) {
                let path = dir.join(name);
                if is_our_link(&path, name) {
                    let _ = std::fs::remove_file(&path);
                }
            }
            if let Some(old_set) = old_set {
                let _ = std::fs::remove_dir_all(old_set);
            }
            Ok(())
        }
    }

    impl Drop for Writer {
        fn drop(&mut self) {
            staging().retain(|s| s != &self.set);
            if self.done {
                return;
            }
            let _ = std::fs::remove_dir_all(&self.set);
            unmake(&self.dir, self.made);
        }
    }

    /// Removes what an unfinished writer made: the directory, or its hidden directory where
    /// no set is current in it (an earlier version's files taken over keep theirs).
    fn unmake(dir: &Path, (made_dir, made_hidden): (bool, bool)) {
        if made_dir {
            let _ = std::fs::remove_dir_all(dir);
        } else if made_hidden && std::fs::symlink_metadata(dir.join(HIDDEN).join(CURRENT)).is_err() {
            let _ = std::fs::remove_dir_all(dir.join(HIDDEN));
        }
    }

    /// The commit of a set into `dir` (see the module's documentation).
    pub(super) fn commit(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), Error> {
        let names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
        let mut writer = Writer::begin(dir, &names)?;
        for (name, bytes) in files {
            writer.write(name, bytes)?;
        }
        writer.finish()
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    fn commit(dir: &Path, files: &[(&str, &str)]) -> Result<(), Error> {
        let mut o = Outputs::new(dir);
        for (name, text) in files {
            o.add(name, text.as_bytes().to_vec());
        }
        o.commit()
    }

    /// The target is checked before a run: a file where the directory goes, or on the way to
    /// it, is refused by name; a fresh nested directory passes, and nothing is left behind.
    #[test]
    fn the_target_is_checked_before_the_run_and_nothing_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a-file");
        std::fs::write(&file, "mine").unwrap();
        let e = check_target(&file).unwrap_err().to_string();
        assert!(e.contains("a-file is not a directory"), "{e}");
        let e = check_target(&file.join("sub")).unwrap_err().to_string();
        assert!(
            e.contains("a-file is not a directory (it is on the way to --out)"),
            "{e}"
        );
        check_target(&dir.path().join("new").join("deeper")).unwrap();
        check_target(dir.path()).unwrap();
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["a-file"]);
    }

    /// The visible names of `dir` (the hidden directory aside).
    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n != HIDDEN)
            .collect();
        v.sort();
        v
    }

    fn read(dir: &Path, name: &str) -> String {
        std::fs::read_to_string(dir.join(name)).unwrap()
    }

    #[test]
    fn a_failed_commit_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        // a name that is no plain file name
        assert!(commit(&target, &[("a.txt", "a"), ("nested/b.txt", "b")]).is_err());
        assert!(!target.exists());
        // over an earlier set, the earlier set stays as it was
        commit(&target, &[("run.json", "1"), ("contact.csv", "1")]).unwrap();
        assert!(commit(&target, &[("run.json", "2"), ("../b.txt", "b")]).is_err());
        assert_eq!(read(&target, "run.json"), "1");
        assert_eq!(listing(dir.path()), ["run"]);
    }

    #[test]
    fn a_new_set_replaces_the_old_as_a_whole_and_keeps_the_users_files() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        commit(
            &target,
            &[("run.json", "1"), ("contact.csv", "1"), ("multipliers.svg", "1")],
        )
        .unwrap();
        // a run without contact: its set has no contact.csv, and none is left behind
        commit(&target, &[("run.json", "2"), ("solution.vtu", "2")]).unwrap();
        assert_eq!(listing(&target), ["run.json", "solution.vtu"]);
        assert_eq!(read(&target, "run.json"), "2");
        // a file and a directory of the user's stay, untouched
        std::fs::write(target.join("notes.txt"), "mine").unwrap();
        std::fs::create_dir(target.join("mine")).unwrap();
        commit(&target, &[("run.json", "3"), ("contact.csv", "3")]).unwrap();
        assert_eq!(listing(&target), ["contact.csv", "mine", "notes.txt", "run.json"]);
        assert_eq!(read(&target, "notes.txt"), "mine");
        // one set in the hidden directory, nothing left beside the output directory
        let sets = std::fs::read_dir(target.join(HIDDEN))
            .unwrap()
            .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with("set-"))
            .count();
        assert_eq!(sets, 1);
        assert_eq!(listing(dir.path()), ["run"]);
    }

    #[test]
    fn a_users_file_named_like_an_output_stops_the_commit_before_anything_changes() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        commit(&target, &[("run.json", "1")]).unwrap();
        std::fs::write(target.join("contact.csv"), "mine").unwrap();
        std::fs::create_dir(target.join("solution.vtu")).unwrap();
        let e = commit(&target, &[("run.json", "2"), ("contact.csv", "2")])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("contact.csv") && e.contains("is not a file of an earlier run"),
            "{e}"
        );
        let e = commit(&target, &[("run.json", "2"), ("solution.vtu", "2")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("solution.vtu"), "{e}");
        assert_eq!(read(&target, "contact.csv"), "mine");
        assert!(target.join("solution.vtu").is_dir());
        assert_eq!(read(&target, "run.json"), "1");
        // a file of the user's named like an output, in a directory no run wrote
        let fresh = dir.path().join("fresh");
        std::fs::create_dir(&fresh).unwrap();
        std::fs::write(fresh.join("run.json"), "mine").unwrap();
        assert!(commit(&fresh, &[("run.json", "1")]).is_err());
        assert_eq!(read(&fresh, "run.json"), "mine");
        assert!(!fresh.join(HIDDEN).exists());
    }

    #[test]
    fn a_linked_directory_dir_dot_dir_parent_and_long_names_are_written_into() {
        let dir = tempfile::tempdir().unwrap();
        // a link to a directory: written through, into its target, the link kept
        let real = dir.path().join("real");
        std::fs::create_dir(&real).unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        commit(&link, &[("run.json", "1")]).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(read(&real, "run.json"), "1");
        // `DIR/.` and `DIR/sub/..` are DIR
        commit(&real.join("."), &[("run.json", "2")]).unwrap();
        assert_eq!(read(&real, "run.json"), "2");
        std::fs::create_dir(real.join("sub")).unwrap();
        commit(&real.join("sub").join(".."), &[("run.json", "3")]).unwrap();
        assert_eq!(read(&real, "run.json"), "3");
        // a name of 200 characters
        let long = dir.path().join("x".repeat(200));
        commit(&long, &[("run.json", "4")]).unwrap();
        assert_eq!(read(&long, "run.json"), "4");
        // (`.`, the working directory, is run by crates/driver/tests/outputs.rs: a test here
        // must not move the working directory of its siblings)
    }

    #[test]
    fn a_set_of_an_earlier_version_is_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        std::fs::create_dir(&target).unwrap();
        for f in ["run.json", "contact.csv"] {
            std::fs::write(target.join(f), "old").unwrap();
        }
        std::fs::write(target.join("notes.txt"), "mine").unwrap();
        std::fs::write(target.join(LEGACY_MANIFEST), "run.json\ncontact.csv\n").unwrap();
        commit(&target, &[("run.json", "new")]).unwrap();
        assert_eq!(listing(&target), ["notes.txt", "run.json"]);
        assert_eq!(read(&target, "run.json"), "new");
    }

    #[cfg(unix)]
    #[test]
    fn a_link_to_nothing_is_refused_and_a_link_to_a_directory_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("out");
        std::os::unix::fs::symlink(dir.path().join("absent"), &link).unwrap();
        let e = commit(&link, &[("run.json", "x")]).unwrap_err();
        assert!(e.to_string().contains("a link to nothing"), "{e}");
        assert!(!dir.path().join("absent").exists());
        std::fs::create_dir(dir.path().join("absent")).unwrap();
        commit(&link, &[("run.json", "x")]).unwrap();
        assert_eq!(read(&dir.path().join("absent"), "run.json"), "x");
    }

    #[test]
    fn runs_into_one_directory_do_not_mix() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        let threads: Vec<_> = (0..8)
            .map(|k| {
                let target = target.clone();
                std::thread::spawn(move || {
                    let text = k.to_string();
                    let files: Vec<(&str, &str)> = if k % 2 == 0 {
                        vec![("run.json", &text), ("contact.csv", &text)]
                    } else {
                        vec![("run.json", &text), ("solution.vtu", &text)]
                    };
                    commit(&target, &files).unwrap();
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
        // one set, whole: every visible file is of it, and they agree
        let files = listing(&target);
        assert_eq!(files.len(), 2, "{files:?}");
        let texts: Vec<String> = files.iter().map(|f| read(&target, f)).collect();
        assert!(texts.iter().all(|t| t == &texts[0]), "{texts:?}");
    }

    #[test]
    fn documents_are_plain_files_replaced_in_place() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("theory.md"), "mine").unwrap();
        let mut d = Outputs::documents(dir.path());
        d.add("stability.md", b"page".to_vec());
        d.commit().unwrap();
        assert!(std::fs::symlink_metadata(dir.path().join("stability.md"))
            .unwrap()
            .is_file());
        assert_eq!(read(dir.path(), "theory.md"), "mine");
        assert_eq!(listing(dir.path()), ["stability.md", "theory.md"]);
    }
}
