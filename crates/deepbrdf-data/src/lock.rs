//! The lock of an output folder: one run writes a folder at a time. A second run that targets the
//! same folder is refused with a message that names the holder's pid; the lock of a run that died
//! (killed, crashed, machine rebooted) is taken over without asking.
//!
//! The lock is an operating-system advisory lock (`File::try_lock`, flock on Unix) on the file
//! [`LOCK_FILE`] inside the folder, which also records the holder's pid and command line for the
//! message. The operating system releases the lock when its holder exits, however it exits, so a
//! stale lock file left by a dead process is simply locked again by the next run; no pid liveness
//! guessing is involved. The file stays in the folder after the run (a hidden file of a few bytes).
//! Taking the lock removes the temporary files a killed run left in the folder
//! ([`remove_stale_temporaries`]).

use crate::error::{DataError, Result};
use crate::files;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Name of the lock file inside a locked folder.
pub const LOCK_FILE: &str = ".deepbrdf.lock";

/// Most bytes of a lock file read back for the refusal message.
const HOLDER_BYTES: u64 = 4096;

/// An exclusive lock on an output folder, held until dropped.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    file: File,
}

impl FolderLock {
    /// Creates `dir` if needed and locks it for this process. Fails with a message naming the
    /// folder and the holder's pid if another live process holds it.
    pub fn acquire(dir: &Path) -> Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
        let path = dir.join(LOCK_FILE);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| DataError::io(&path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let holder = read_holder(&mut file);
                return Err(DataError::Invalid(format!(
                    "{}: another run is writing this folder ({holder}); wait for it to finish or \
                     choose another output folder",
                    dir.display()
                )));
            }
            Err(TryLockError::Error(e)) => return Err(DataError::io(&path, e)),
        }
        let record = format!(
            "pid {}\ncommand {}\n",
            std::process::id(),
            std::env::args().collect::<Vec<_>>().join(" ")
        );
        file.set_len(0).map_err(|e| DataError::io(&path, e))?;
        file.seek(SeekFrom::Start(0)).map_err(|e| DataError::io(&path, e))?;
        file.write_all(record.as_bytes()).map_err(|e| DataError::io(&path, e))?;
        file.sync_all().map_err(|e| DataError::io(&path, e))?;
        // Whatever a killed run of this folder was writing is garbage now.
        remove_stale_temporaries(dir)?;
        Ok(Self { path, file })
    }

    /// The lock file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // The file stays (removing it would let a run that opened it just before, and one that
        // creates it anew just after, both hold "the" lock); only the lock is released.
        let _ = self.file.unlock();
    }
}

/// The holder's record (pid and command) for the refusal message, best effort.
fn read_holder(file: &mut File) -> String {
    let mut text = String::new();
    if file.seek(SeekFrom::Start(0)).is_err()
        || file.take(HOLDER_BYTES).read_to_string(&mut text).is_err()
    {
        return "holder unknown".into();
    }
    let fields: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    if fields.is_empty() {
        "holder unknown".into()
    } else {
        fields.join(", ")
    }
}

/// Deepest subfolder of a locked folder searched for stale temporary files.
const MAX_DEPTH: usize = 8;

/// Removes the temporary files of [`crate::files::write_atomic_parts`] in `dir` and its
/// subfolders (links not followed, at most 8 levels deep) and returns how many it removed. A
/// writer killed between creating its temporary file and renaming it (SIGKILL, power loss)
/// cannot remove it itself; the file never carries a final name, so nothing reads it, but it
/// takes space. Called while holding `dir`'s [`FolderLock`] (no live run writes there); a
/// subfolder with a lock file of its own belongs to its own run and is left to it.
fn remove_stale_temporaries(dir: &Path) -> Result<usize> {
    fn sweep(dir: &Path, depth: usize) -> Result<usize> {
        let mut removed = 0;
        let entries = std::fs::read_dir(dir).map_err(|e| DataError::io(dir, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| DataError::io(dir, e))?;
            let path = entry.path();
            let kind = entry.file_type().map_err(|e| DataError::io(&path, e))?;
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if kind.is_file()
                && name.starts_with(files::TEMP_PREFIX)
                && name.ends_with(files::TEMP_SUFFIX)
            {
                std::fs::remove_file(&path).map_err(|e| DataError::io(&path, e))?;
                removed += 1;
            } else if kind.is_dir() && depth < MAX_DEPTH && !path.join(LOCK_FILE).exists() {
                removed += sweep(&path, depth + 1)?;
            }
        }
        Ok(removed)
    }
    sweep(dir, 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_temporaries_are_removed_outside_other_runs_folders() -> TestResult {
        let dir = tempfile::tempdir()?;
        let root = dir.path();
        std::fs::create_dir_all(root.join("model"))?;
        std::fs::create_dir_all(root.join("other"))?;
        files::write_atomic(&root.join("kept.bin"), b"kept")?;
        for p in [".deepbrdf-a1.tmp", "model/.deepbrdf-b2.tmp", "other/.deepbrdf-c3.tmp"] {
            std::fs::write(root.join(p), b"half")?;
        }
        // Not ours by name; and a folder locked by (the file of) another run.
        std::fs::write(root.join("notes.tmp"), b"user")?;
        std::fs::write(root.join("other").join(LOCK_FILE), b"pid 1\n")?;
        assert_eq!(remove_stale_temporaries(root)?, 2);
        assert!(!root.join(".deepbrdf-a1.tmp").exists());
        assert!(!root.join("model/.deepbrdf-b2.tmp").exists());
        for kept in ["kept.bin", "notes.tmp", "other/.deepbrdf-c3.tmp"] {
            assert!(root.join(kept).exists(), "{kept}");
        }
        Ok(())
    }

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    #[test]
    fn a_second_lock_is_refused_with_the_holders_pid_and_freed_on_drop() -> TestResult {
        let dir = tempfile::tempdir()?;
        let out = dir.path().join("run");
        let first = FolderLock::acquire(&out)?;
        let err = FolderLock::acquire(&out).expect_err("second lock must be refused").to_string();
        assert!(err.contains("another run is writing"), "{err}");
        assert!(err.contains(&format!("pid {}", std::process::id())), "{err}");
        assert!(err.contains(&out.display().to_string()), "{err}");
        drop(first);
        let again = FolderLock::acquire(&out)?;
        assert!(again.path().exists());
        Ok(())
    }

    #[test]
    fn a_stale_lock_file_of_a_dead_process_is_taken_over() -> TestResult {
        let dir = tempfile::tempdir()?;
        // What a killed run leaves: the file with its record, but no process holding the lock.
        std::fs::write(dir.path().join(LOCK_FILE), "pid 999999999\ncommand experiments train\n")?;
        let lock = FolderLock::acquire(dir.path())?;
        let record = std::fs::read_to_string(lock.path())?;
        assert!(record.starts_with(&format!("pid {}\n", std::process::id())), "{record}");
        Ok(())
    }

    #[test]
    fn a_folder_that_is_a_file_is_an_error_naming_it() -> TestResult {
        let dir = tempfile::tempdir()?;
        let file = dir.path().join("not-a-dir");
        std::fs::write(&file, b"x")?;
        let err = FolderLock::acquire(&file).expect_err("a file is no folder").to_string();
        assert!(err.contains("not-a-dir"), "{err}");
        Ok(())
    }
}
