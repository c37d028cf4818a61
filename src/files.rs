//! Files in and out, safely: input files are read only when they are regular files within a
//! size limit (a device such as `/dev/zero` would be read for ever), and output is written to
//! a temporary place and moved over the old output only once complete, so that a failed run
//! never leaves a partial file, or a mix of old and new files, in place of a good output.

use crate::error::{Error, Result};
use std::io::Read;
use std::path::{Path, PathBuf};

/// The whole of the regular file `path` if it holds at most `max_bytes` bytes (a limit of
/// [`crate::limits`]). `what` names the kind of file in the error (`"a mesh file"`).
pub fn read_bounded(path: &Path, max_bytes: u64, what: &str) -> Result<Vec<u8>> {
    // Asked before opening: opening a named pipe waits for a writer, possibly for ever.
    let metadata = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    let refuse = |msg: String| Error::io(path, std::io::Error::other(msg));
    if !metadata.is_file() {
        return Err(refuse(format!("not a regular file (a folder, device or pipe): {what} must be a file")));
    }
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    if metadata.len() > max_bytes {
        let size = format!("{} bytes", metadata.len());
        return Err(refuse(crate::limits::exceeded(what, size, format!("{max_bytes} bytes"))));
    }
    // A file can grow while it is read (or report no size, as /proc files do): read one byte
    // past the limit to tell.
    let mut bytes = Vec::with_capacity(metadata.len() as usize);
    file.take(max_bytes + 1).read_to_end(&mut bytes).map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(refuse(format!("{what} grew past tessera's limit of {max_bytes} bytes while it was read")));
    }
    Ok(bytes)
}

/// [`read_bounded`] for a text file, which must be UTF-8.
pub fn read_text_bounded(path: &Path, max_bytes: u64, what: &str) -> Result<String> {
    String::from_utf8(read_bounded(path, max_bytes, what)?).map_err(|e| {
        Error::io(
            path,
            std::io::Error::other(format!("{what} is not UTF-8 text (byte {})", e.utf8_error().valid_up_to())),
        )
    })
}

/// A temporary name beside `path`, in the same folder so that renaming it is atomic.
fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// Write `path` through `write`, which writes the temporary file it is given; the temporary
/// file is renamed over `path` only if `write` succeeds, and removed otherwise.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let tmp = temporary_path(path);
    match write(&tmp) {
        Ok(()) => std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            Error::io(path, e)
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// An output folder written as a whole: files go to a hidden staging folder beside it, and
/// [`StagedFolder::commit`] moves them into the folder (created if needed) only once all are
/// written. Dropped without a commit (an error on the way), the staging folder is removed and
/// the output folder is as it was. Files of the output folder that the run does not write are
/// left alone.
#[derive(Debug)]
pub struct StagedFolder {
    target: PathBuf,
    staging: PathBuf,
    committed: bool,
}

impl StagedFolder {
    /// Stage the output folder `target`; an error if it exists and is not a folder.
    pub fn new(target: &Path) -> Result<Self> {
        if target.exists() && !target.is_dir() {
            return Err(Error::io(target, std::io::Error::other("exists and is not a folder")));
        }
        // A file name is needed for the staging folder's name: `.` and `..` have none.
        let absolute = std::path::absolute(target).map_err(|e| Error::io(target, e))?;
        let normal: PathBuf = absolute.components().collect();
        let staging = temporary_path(&normal);
        let parent = staging.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(|e| Error::io(&staging, e))?;
        }
        std::fs::create_dir(&staging).map_err(|e| Error::io(&staging, e))?;
        Ok(StagedFolder { target: target.to_path_buf(), staging, committed: false })
    }

    /// Where the files are written until the commit: `join` the output's relative paths to it.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Move every staged file into the output folder (each rename is atomic), and return their
    /// final paths.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        collect_files(&self.staging, Path::new(""), &mut files)?;
        // Refuse before moving anything if a file cannot land (a folder in its place), so that
        // the folder ends with all the new files or none.
        for relative in &files {
            let to = self.target.join(relative);
            if to.is_dir() || to.ancestors().skip(1).take(relative.components().count()).any(Path::is_file) {
                return Err(Error::io(&to, std::io::Error::other("cannot be written: a folder or file is in the way")));
            }
        }
        let mut moved = Vec::with_capacity(files.len());
        for relative in files {
            let to = self.target.join(&relative);
            if let Some(folder) = to.parent() {
                std::fs::create_dir_all(folder).map_err(|e| Error::io(folder, e))?;
            }
            std::fs::rename(self.staging.join(&relative), &to).map_err(|e| Error::io(&to, e))?;
            moved.push(to);
        }
        self.committed = true;
        let _ = std::fs::remove_dir_all(&self.staging);
        Ok(moved)
    }
}

impl Drop for StagedFolder {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// The files under `root/relative`, as paths relative to `root`, in a fixed order.
fn collect_files(root: &Path, relative: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let folder = root.join(relative);
    let mut entries: Vec<_> = std::fs::read_dir(&folder)
        .map_err(|e| Error::io(&folder, e))?
        .collect::<std::io::Result<_>>()
        .map_err(|e| Error::io(&folder, e))?;
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let path = relative.join(entry.file_name());
        if entry.file_type().map_err(|e| Error::io(entry.path(), e))?.is_dir() {
            collect_files(root, &path, out)?;
        } else {
            out.push(path);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("keep.exr");
        std::fs::write(&path, b"good").unwrap();
        let result = write_atomically(&path, |_| Err(Error::image(&path, "simulated failure")));
        assert!(result.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"good");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn bounded_reads_refuse_devices_and_large_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.obj");
        std::fs::write(&path, b"0123456789").unwrap();
        assert_eq!(read_bounded(&path, 10, "a mesh file").unwrap().len(), 10);
        let msg = read_bounded(&path, 9, "a mesh file").unwrap_err().to_string();
        assert!(msg.contains("a.obj") && msg.contains("limit of 9"), "{msg}");
        let msg = read_bounded(Path::new("/dev/zero"), 1 << 20, "a scene file").unwrap_err().to_string();
        assert!(msg.contains("/dev/zero") && msg.contains("not a regular file"), "{msg}");
        let msg = read_bounded(dir.path(), 1 << 20, "a scene file").unwrap_err().to_string();
        assert!(msg.contains("not a regular file"), "{msg}");
        // A named pipe without a writer: refused, not waited on.
        let fifo = dir.path().join("fifo");
        if std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
            let msg = read_bounded(&fifo, 1 << 20, "a mesh file").unwrap_err().to_string();
            assert!(msg.contains("not a regular file"), "{msg}");
        }
        std::fs::write(&path, b"\xff\xfe").unwrap();
        assert!(read_text_bounded(&path, 10, "a scene file").unwrap_err().to_string().contains("not UTF-8"));
    }

    #[test]
    fn staged_folder_replaces_files_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("a.txt"), b"old").unwrap();
        std::fs::write(out.join("mine.txt"), b"user's").unwrap();
        {
            let staged = StagedFolder::new(&out).unwrap();
            std::fs::write(staged.path().join("a.txt"), b"new").unwrap();
            // Dropped without a commit: a failure halfway.
        }
        assert_eq!(std::fs::read(out.join("a.txt")).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "the staging folder is removed");
        let staged = StagedFolder::new(&out).unwrap();
        std::fs::write(staged.path().join("a.txt"), b"new").unwrap();
        std::fs::create_dir(staged.path().join("sub")).unwrap();
        std::fs::write(staged.path().join("sub/b.txt"), b"b").unwrap();
        let files = staged.commit().unwrap();
        assert_eq!(files, [out.join("a.txt"), out.join("sub/b.txt")]);
        assert_eq!(std::fs::read(out.join("a.txt")).unwrap(), b"new");
        assert_eq!(std::fs::read(out.join("sub/b.txt")).unwrap(), b"b");
        assert_eq!(std::fs::read(out.join("mine.txt")).unwrap(), b"user's");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // A new folder is created only at the commit.
        let fresh = dir.path().join("fresh");
        drop(StagedFolder::new(&fresh).unwrap());
        assert!(!fresh.exists());
    }
}
