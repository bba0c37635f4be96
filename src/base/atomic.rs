//! The one atomic writer: missions, exports, recordings, the recovery copy
//! and every file the CLI writes go through here, so none is ever left half
//! written and none changes the permissions the user gave it.
//!
//! A file is written to a temporary file beside it, synced and renamed over
//! it. The result has the permissions a plain `File::create` would give a
//! new file (0666 less the umask: 0644 under the usual umask 022), or the
//! mode of the file it replaces: a ground station running as another user,
//! or a shared folder, reads an export as it reads any file the user
//! writes, and a private mission stays private.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

/// A file being written: a temporary file beside its destination that
/// becomes the destination on [`Pending::commit`]. Dropped uncommitted, it
/// is removed and the destination is untouched.
#[derive(Debug)]
pub struct Pending {
    tmp: NamedTempFile,
    path: PathBuf,
}

/// Starts writing `path`: creates the temporary file beside it.
pub fn create(path: &Path) -> io::Result<Pending> {
    let dir = directory_of(path);
    let mut builder = tempfile::Builder::new();
    builder.prefix(".skyform-save-").suffix(".tmp");
    // Created with the mode `File::create` asks for, so the kernel applies
    // the umask as it does for any new file (tempfile's own default is 0600).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    Ok(Pending {
        tmp: builder.tempfile_in(dir)?,
        path: path.to_owned(),
    })
}

/// Writes `bytes` to `path` through a synced temporary file and a rename.
pub fn write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut pending = create(path)?;
    pending.file().write_all(bytes)?;
    pending.commit()
}

impl Pending {
    /// Where the bytes go until the commit (for a writer that opens the
    /// file itself, such as Rerun's file sink).
    pub fn temporary_path(&self) -> &Path {
        self.tmp.path()
    }

    /// The file this becomes on commit.
    pub fn destination(&self) -> &Path {
        &self.path
    }

    pub fn file(&mut self) -> &mut fs::File {
        self.tmp.as_file_mut()
    }

    /// Makes the written bytes the destination's: keeps the mode of the
    /// file replaced, syncs, renames, and syncs the directory.
    pub fn commit(self) -> io::Result<()> {
        let Pending { tmp, path } = self;
        if let Ok(meta) = fs::metadata(&path) {
            tmp.as_file().set_permissions(meta.permissions())?;
        }
        tmp.as_file().sync_all()?;
        tmp.persist(&path).map_err(|e| e.error)?;
        // Make the rename itself durable. Not every platform lets a directory
        // be opened and synced; the data is already safe, so that failure is
        // ignored.
        if let Ok(d) = fs::File::open(directory_of(&path)) {
            let _ = d.sync_all();
        }
        Ok(())
    }
}

fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    fn mode(path: &Path) -> u32 {
        fs::metadata(path).unwrap().permissions().mode() & 0o777
    }

    /// Issue 24, item 9: a new file gets what `File::create` gives (the
    /// umask applied), a replaced one keeps its mode.
    #[test]
    fn atomic_writes_create_files_as_file_create_does_and_keep_a_replaced_mode() {
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.txt");
        fs::File::create(&plain).unwrap();
        let atomic = dir.path().join("atomic.txt");
        write(&atomic, b"one").unwrap();
        assert_eq!(mode(&atomic), mode(&plain));
        assert_ne!(mode(&atomic), 0o600, "not tempfile's private default");

        fs::set_permissions(&atomic, fs::Permissions::from_mode(0o640)).unwrap();
        write(&atomic, b"two").unwrap();
        assert_eq!(mode(&atomic), 0o640);
        assert_eq!(fs::read(&atomic).unwrap(), b"two");
    }

    /// A file written by someone else at the temporary path (a recording's
    /// sink) becomes the destination's on commit, keeping its mode; dropped
    /// uncommitted, it leaves the destination as it was.
    #[test]
    fn a_pending_file_replaces_its_destination_only_when_committed() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run.rrd");
        fs::write(&target, b"old").unwrap();
        fs::set_permissions(&target, fs::Permissions::from_mode(0o604)).unwrap();

        let abandoned = create(&target).unwrap();
        fs::write(abandoned.temporary_path(), b"half").unwrap();
        drop(abandoned);
        assert_eq!(fs::read(&target).unwrap(), b"old");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary left"
        );

        let pending = create(&target).unwrap();
        fs::write(pending.temporary_path(), b"new").unwrap();
        pending.commit().unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new");
        assert_eq!(mode(&target), 0o604);
    }
}
