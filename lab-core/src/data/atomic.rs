//! Atomic writes: every file the lab writes goes to a temporary file in
//! the same folder and is renamed over its name only once complete, so a
//! crash, a full disk or a Ctrl-C leaves the old file whole (or none),
//! never half of a new one.

use crate::error::LabError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A file being written; it appears under its name at [`Self::commit`],
/// and the temporary file is removed if it is dropped before.
pub struct AtomicFile {
    tmp: PathBuf,
    dest: PathBuf,
    w: Option<std::io::BufWriter<std::fs::File>>,
}

/// The temporary name beside `dest`: hidden, and unique to this process.
fn temporary(dest: &Path) -> PathBuf {
    let name = dest
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    dest.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

impl AtomicFile {
    pub fn create(dest: &Path) -> Result<Self, LabError> {
        let tmp = temporary(dest);
        let f = std::fs::File::create(&tmp).map_err(|e| LabError::io(dest, e))?;
        Ok(Self {
            tmp,
            dest: dest.to_owned(),
            w: Some(std::io::BufWriter::with_capacity(1 << 16, f)),
        })
    }

    pub fn path(&self) -> &Path {
        &self.dest
    }

    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> Result<(), LabError> {
        let io = |e: std::io::Error| LabError::io(&self.dest, e);
        let w = self
            .w
            .take()
            .ok_or_else(|| io(std::io::Error::other("already committed")))?;
        let f = w.into_inner().map_err(|e| io(e.into_error()))?;
        f.sync_all().map_err(io)?;
        drop(f);
        std::fs::rename(&self.tmp, &self.dest).map_err(io)
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self.w.as_mut() {
            Some(w) => w.write(buf),
            None => Err(std::io::Error::other("committed")),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.w.as_mut().map_or(Ok(()), |w| w.flush())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.w.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), LabError> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes.as_ref())
        .map_err(|e| LabError::io(path, e))?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_write_dropped_before_commit_leaves_the_old_file_whole() {
        let dir = std::env::temp_dir().join(format!("gyro-lab-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.csv");
        write(&p, "old\n").unwrap();
        {
            let mut f = AtomicFile::create(&p).unwrap();
            f.write_all(b"half of a new fi").unwrap();
            // Dropped: a crash before the rename.
        }
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old\n");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "no temporary file left"
        );
        write(&p, "new\n").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new\n");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
