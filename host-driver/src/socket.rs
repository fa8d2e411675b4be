//! Where pend listens, made safe against other users of the machine.
//!
//! The socket carries every pen event, and whoever can replace it sees the user's pen. So:
//!
//! - The default directory (`$XDG_RUNTIME_DIR/penscape`, or `/tmp/penscape-UID` without one) is
//!   created by pend with mode 0700. One that already exists is used only if it is a real
//!   directory (not a symlink: checked with `lstat`), owned by this user, and closed to group and
//!   others; anything else is refused with what is wrong, never repaired in place — it may be
//!   another user's trap.
//! - For a socket path given on the command line, its directory is created 0700 if missing; an
//!   existing one must not be a symlink, and must be owned by this user or root and not writable
//!   by group or others — not even sticky like `/tmp`: the sticky bit stops others renaming the
//!   socket, but not creating `PATH.lock` or a socket of theirs at the path before pend does
//!   (pend would then take their squat for "another pend", and clients would talk to theirs).
//! - The lock file and a socket found at the path must be this user's (a squat in a folder that
//!   was shared once is named, not taken for another pend). Clients check who serves them too
//!   ([`crate::client`]).
//! - The socket is bound under a umask of 0177, so it is owner-only from the moment it exists
//!   (no window between `bind` and `chmod`).
//! - Only a *socket* nobody answers on is removed as stale (a crashed pend left it); a regular
//!   file, a folder or a symlink at the path is an error naming it, and a socket that answers is
//!   another pend.
//! - The pend at a path holds `PATH.lock` (an owner-only file beside the socket, `flock`ed for as
//!   long as it listens) from before it looks at the socket: pends started together on a stale
//!   socket would otherwise each find it dead, and one could remove the socket another had just
//!   bound, leaving a pend nobody can reach. The kernel drops the lock when pend dies, however it
//!   dies; the file stays (removing it would reopen the race).

use std::ffi::OsString;
use std::fs::{DirBuilder, File, Metadata, OpenOptions};
use std::io;
use std::os::unix::fs::{DirBuilderExt, FileTypeExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};

use nix::errno::Errno;
use nix::fcntl::{Flock, FlockArg, OFlag};
use nix::sys::stat::{Mode, umask};

/// Why pend cannot listen where it was asked to.
#[derive(Debug, thiserror::Error)]
pub enum SocketError {
    /// The directory, or the path itself, is a symbolic link.
    #[error("{0} is a symbolic link; pend does not follow links for its socket (remove it, or choose --socket)")]
    Symlink(PathBuf),
    /// Something that is not a directory stands where the socket's directory should be.
    #[error("{0} is not a directory")]
    NotADirectory(PathBuf),
    /// The directory belongs to someone else.
    #[error(
        "{path} belongs to user {owner}, not to you (user {uid}); another user may control it — remove it or choose --socket"
    )]
    NotOwned {
        /// The directory.
        path: PathBuf,
        /// Its owner's uid.
        owner: u32,
        /// This process's uid.
        uid: u32,
    },
    /// The directory is open to other users.
    #[error("{path} has mode {mode:04o}; it must be closed to other users (chmod 700 {path}) or removed")]
    OpenToOthers {
        /// The directory.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
    },
    /// A chosen socket folder that other users can create files in.
    #[error(
        "{path} has mode {mode:04o}: other users can create files in it and take pend's socket or its lock before pend does; put the socket in a folder of your own (the default, or e.g. --socket {path}/penscape-{uid}/pend.sock, which pend makes 0700)"
    )]
    SharedFolder {
        /// The directory.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
        /// This process's uid.
        uid: u32,
    },
    /// A file at pend's socket path or its lock belongs to another user.
    #[error(
        "{path} belongs to user {owner}, not to you (user {uid}); pend will not use it (remove it or choose --socket)"
    )]
    NotYours {
        /// The socket or lock file.
        path: PathBuf,
        /// Its owner's uid.
        owner: u32,
        /// This process's uid.
        uid: u32,
    },
    /// Something that is not a socket stands at the socket's path.
    #[error("{0} exists and is not a socket; pend will not remove it (choose another --socket)")]
    NotASocket(PathBuf),
    /// Another pend answers on the socket.
    #[error("{0} is in use by another pend")]
    InUse(PathBuf),
    /// The system refused an operation.
    #[error("cannot {what} {path}: {cause}")]
    Io {
        /// What was being done.
        what: &'static str,
        /// On what.
        path: PathBuf,
        /// The system's reason (not a `source`, so a chain of errors prints it once).
        cause: io::Error,
    },
}

/// This process's user id.
pub fn uid() -> u32 {
    nix::unistd::getuid().as_raw()
}

/// The default socket: `$XDG_RUNTIME_DIR/penscape/pend.sock`, or `/tmp/penscape-UID/pend.sock`
/// when `XDG_RUNTIME_DIR` is unset or empty.
pub fn default_path() -> PathBuf {
    default_path_from(std::env::var_os("XDG_RUNTIME_DIR"), uid())
}

fn default_path_from(runtime_dir: Option<OsString>, uid: u32) -> PathBuf {
    match runtime_dir {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir).join("penscape/pend.sock"),
        _ => PathBuf::from(format!("/tmp/penscape-{uid}/pend.sock")),
    }
}

/// pend's socket, bound, and the lock that makes the path this pend's while it listens.
#[derive(Debug)]
pub struct Bound {
    /// The listening socket.
    pub listener: UnixListener,
    /// Released when this is dropped (or the process ends).
    _lock: Flock<File>,
}

/// Binds pend's socket at `path`. `private_dir`: the directory is pend's own (the default
/// location) and is held to the strict rule — owned by this user, mode 0700 or tighter.
pub fn bind(path: &Path, private_dir: bool) -> Result<Bound, SocketError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    prepare_dir(&dir, private_dir)?;
    let lock = take_lock(path)?;
    clear_stale(path)?;
    // Owner-only from creation: the umask is the process's, so restore it at once.
    let old = umask(Mode::from_bits_truncate(0o177));
    let bound = UnixListener::bind(path);
    umask(old);
    let listener = bound.map_err(|cause| SocketError::Io {
        what: "listen on",
        path: path.to_path_buf(),
        cause,
    })?;
    Ok(Bound { listener, _lock: lock })
}

/// Takes `PATH.lock`, owner-only and not through a symlink; another pend holding it is
/// [`SocketError::InUse`].
fn take_lock(path: &Path) -> Result<Flock<File>, SocketError> {
    let mut name = path.as_os_str().to_owned();
    name.push(".lock");
    let lock_path = PathBuf::from(name);
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .mode(0o600)
        .custom_flags(OFlag::O_NOFOLLOW.bits() | OFlag::O_CLOEXEC.bits())
        .open(&lock_path)
        .map_err(|cause| SocketError::Io {
            what: "open the lock",
            path: lock_path.clone(),
            cause,
        })?;
    // O_CREAT opened one that was there already: only ours is ours to hold.
    let owner = file
        .metadata()
        .map_err(|cause| SocketError::Io {
            what: "inspect",
            path: lock_path.clone(),
            cause,
        })?
        .uid();
    if owner != uid() {
        return Err(SocketError::NotYours {
            path: lock_path,
            owner,
            uid: uid(),
        });
    }
    match Flock::lock(file, FlockArg::LockExclusiveNonblock) {
        Ok(lock) => Ok(lock),
        Err((_, Errno::EWOULDBLOCK)) => Err(SocketError::InUse(path.to_path_buf())),
        Err((_, errno)) => Err(SocketError::Io {
            what: "lock",
            path: lock_path,
            cause: io::Error::from(errno),
        }),
    }
}

/// Makes `dir` (0700) if it is missing, and checks an existing one.
fn prepare_dir(dir: &Path, private_dir: bool) -> Result<(), SocketError> {
    match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            // Parents as the system makes them; the last level is ours and private.
            if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent).map_err(|cause| SocketError::Io {
                    what: "create the folder",
                    path: parent.to_path_buf(),
                    cause,
                })?;
            }
            match DirBuilder::new().mode(0o700).create(dir) {
                Ok(()) => {}
                // Made by someone else between our look and our mkdir: check theirs below.
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
                Err(cause) => {
                    return Err(SocketError::Io {
                        what: "create the folder",
                        path: dir.to_path_buf(),
                        cause,
                    });
                }
            }
            let meta = lstat(dir)?;
            check_dir(dir, &meta, private_dir)
        }
        Err(cause) => Err(SocketError::Io {
            what: "inspect",
            path: dir.to_path_buf(),
            cause,
        }),
        Ok(meta) => check_dir(dir, &meta, private_dir),
    }
}

fn lstat(path: &Path) -> Result<Metadata, SocketError> {
    std::fs::symlink_metadata(path).map_err(|cause| SocketError::Io {
        what: "inspect",
        path: path.to_path_buf(),
        cause,
    })
}

fn check_dir(dir: &Path, meta: &Metadata, private_dir: bool) -> Result<(), SocketError> {
    if meta.file_type().is_symlink() {
        return Err(SocketError::Symlink(dir.to_path_buf()));
    }
    if !meta.is_dir() {
        return Err(SocketError::NotADirectory(dir.to_path_buf()));
    }
    let me = uid();
    let mode = meta.permissions().mode() & 0o7777;
    if private_dir {
        if meta.uid() != me {
            return Err(SocketError::NotOwned {
                path: dir.to_path_buf(),
                owner: meta.uid(),
                uid: me,
            });
        }
        if mode & 0o077 != 0 {
            return Err(SocketError::OpenToOthers {
                path: dir.to_path_buf(),
                mode,
            });
        }
    } else {
        if meta.uid() != me && meta.uid() != 0 {
            return Err(SocketError::NotOwned {
                path: dir.to_path_buf(),
                owner: meta.uid(),
                uid: me,
            });
        }
        // Writable by group or others, sticky or not: they could squat the names pend uses.
        if mode & 0o022 != 0 {
            return Err(SocketError::SharedFolder {
                path: dir.to_path_buf(),
                mode,
                uid: me,
            });
        }
    }
    Ok(())
}

/// Removes a socket at `path` that nobody answers on; refuses anything else.
fn clear_stale(path: &Path) -> Result<(), SocketError> {
    let meta = match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(cause) => {
            return Err(SocketError::Io {
                what: "inspect",
                path: path.to_path_buf(),
                cause,
            });
        }
        Ok(m) => m,
    };
    if meta.file_type().is_symlink() {
        return Err(SocketError::Symlink(path.to_path_buf()));
    }
    if !meta.file_type().is_socket() {
        return Err(SocketError::NotASocket(path.to_path_buf()));
    }
    if meta.uid() != uid() {
        return Err(SocketError::NotYours {
            path: path.to_path_buf(),
            owner: meta.uid(),
            uid: uid(),
        });
    }
    match UnixStream::connect(path) {
        Ok(_) => Err(SocketError::InUse(path.to_path_buf())),
        // Refused: a socket left by a crashed pend.
        Err(e) if e.kind() == io::ErrorKind::ConnectionRefused => {
            std::fs::remove_file(path).map_err(|cause| SocketError::Io {
                what: "remove the stale socket",
                path: path.to_path_buf(),
                cause,
            })
        }
        Err(cause) => Err(SocketError::Io {
            what: "connect to",
            path: path.to_path_buf(),
            cause,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode_of(p: &Path) -> u32 {
        std::fs::symlink_metadata(p).expect("exists").permissions().mode() & 0o7777
    }

    #[test]
    fn the_default_path_follows_the_runtime_dir() {
        assert_eq!(
            default_path_from(Some("/run/user/1000".into()), 1000),
            PathBuf::from("/run/user/1000/penscape/pend.sock")
        );
        assert_eq!(
            default_path_from(None, 1000),
            PathBuf::from("/tmp/penscape-1000/pend.sock")
        );
        assert_eq!(
            default_path_from(Some("".into()), 7),
            PathBuf::from("/tmp/penscape-7/pend.sock")
        );
    }

    #[test]
    fn a_new_private_dir_and_socket_are_owner_only() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let dir = tmp.path().join("penscape");
        let path = dir.join("pend.sock");
        let listener = bind(&path, true).expect("binds");
        assert_eq!(mode_of(&dir), 0o700);
        assert_eq!(mode_of(&path) & 0o777, 0o600, "no access for others from the start");
        drop(listener);
    }

    #[test]
    fn a_private_dir_open_to_others_is_refused_not_repaired() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let dir = tmp.path().join("penscape");
        std::fs::create_dir(&dir).expect("mkdir");
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).expect("chmod");
        let e = bind(&dir.join("pend.sock"), true).expect_err("refused");
        assert!(matches!(e, SocketError::OpenToOthers { mode: 0o777, .. }), "{e}");
        assert!(e.to_string().contains("chmod 700"), "{e}");
        assert_eq!(mode_of(&dir), 0o777, "left as found");
        assert!(!dir.join("pend.sock").exists());
    }

    #[test]
    fn a_symlinked_dir_is_refused() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let elsewhere = tmp.path().join("elsewhere");
        std::fs::create_dir(&elsewhere).expect("mkdir");
        std::fs::set_permissions(&elsewhere, std::fs::Permissions::from_mode(0o700)).expect("chmod");
        let link = tmp.path().join("penscape");
        std::os::unix::fs::symlink(&elsewhere, &link).expect("symlink");
        let e = bind(&link.join("pend.sock"), true).expect_err("refused");
        assert!(matches!(e, SocketError::Symlink(_)), "{e}");
        let e = bind(&link.join("pend.sock"), false).expect_err("refused for a chosen path too");
        assert!(matches!(e, SocketError::Symlink(_)), "{e}");
    }

    #[test]
    fn a_dir_of_another_user_is_refused() {
        // Only root can give a folder away; elsewhere this case cannot be made.
        if uid() != 0 {
            eprintln!("skipped: giving a folder to another user needs root");
            return;
        }
        let tmp = tempfile::tempdir().expect("tempdir");
        let dir = tmp.path().join("penscape");
        DirBuilder::new().mode(0o700).create(&dir).expect("mkdir");
        nix::unistd::chown(&dir, Some(nix::unistd::Uid::from_raw(65534)), None).expect("chown");
        let e = bind(&dir.join("pend.sock"), true).expect_err("refused");
        assert!(matches!(e, SocketError::NotOwned { owner: 65534, .. }), "{e}");
        let e = bind(&dir.join("pend.sock"), false).expect_err("refused for a chosen path too");
        assert!(matches!(e, SocketError::NotOwned { owner: 65534, .. }), "{e}");
    }

    /// Issue 47 item 8: in a shared folder like `/tmp` (sticky) another user could make the lock
    /// or a socket at the path first; pend took that for another pend. Such a folder is refused
    /// for what it is, with a folder of one's own suggested; one closed to others is taken.
    #[test]
    fn a_chosen_path_in_a_shared_dir_sticky_or_not_is_refused() {
        let tmp = tempfile::tempdir().expect("tempdir");
        for mode in [0o1777, 0o777, 0o1770, 0o775] {
            let dir = tmp.path().join(format!("shared-{mode:o}"));
            std::fs::create_dir(&dir).expect("mkdir");
            std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(mode)).expect("chmod");
            let e = bind(&dir.join("pend.sock"), false).expect_err("refused");
            assert!(
                matches!(e, SocketError::SharedFolder { mode: m, .. } if m == mode),
                "{e}"
            );
            assert!(e.to_string().contains("folder of your own"), "{e}");
            assert!(!dir.join("pend.sock.lock").exists(), "nothing made in it");
        }
        let own = tmp.path().join("own");
        std::fs::create_dir(&own).expect("mkdir");
        std::fs::set_permissions(&own, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        bind(&own.join("pend.sock"), false).expect("closed to others: taken");
    }

    /// A lock file or a socket at the path that another user made (as root: chowned) is named as
    /// theirs, not taken for another pend nor held or removed.
    #[test]
    fn a_squatted_lock_or_socket_of_another_user_is_named_as_theirs() {
        if uid() != 0 {
            eprintln!("skipped: giving a file to another user needs root");
            return;
        }
        let other = Some(nix::unistd::Uid::from_raw(65534));
        let tmp = tempfile::tempdir().expect("tempdir");
        let path = tmp.path().join("pend.sock");
        let lock = tmp.path().join("pend.sock.lock");
        std::fs::write(&lock, "").expect("squat the lock");
        nix::unistd::chown(&lock, other, None).expect("chown");
        let e = bind(&path, false).expect_err("refused");
        assert!(matches!(e, SocketError::NotYours { owner: 65534, .. }), "{e}");
        std::fs::remove_file(&lock).expect("rm");

        let squat = UnixListener::bind(&path).expect("a fake socket");
        nix::unistd::chown(&path, other, None).expect("chown");
        let e = bind(&path, false).expect_err("refused");
        assert!(matches!(e, SocketError::NotYours { owner: 65534, .. }), "{e}");
        assert!(e.to_string().contains("user 65534"), "{e}");
        drop(squat);
        assert!(path.exists(), "not removed");
    }

    #[test]
    fn only_a_dead_socket_is_replaced() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let path = tmp.path().join("pend.sock");

        std::fs::write(&path, "my notes").expect("write");
        let e = bind(&path, false).expect_err("a regular file is not stale");
        assert!(matches!(e, SocketError::NotASocket(_)), "{e}");
        assert_eq!(std::fs::read_to_string(&path).expect("kept"), "my notes");
        std::fs::remove_file(&path).expect("rm");

        let live = bind(&path, false).expect("binds");
        let e = bind(&path, false).expect_err("in use");
        assert!(matches!(e, SocketError::InUse(_)), "{e}");
        drop(live);
        // The listener is gone, its file remains and refuses connections: stale.
        assert!(path.exists());
        bind(&path, false).expect("a stale socket is replaced");
    }

    /// Pends started together on a stale socket: each sees it dead, and without a lock one could
    /// remove the socket another had just bound in its place, leaving two pends, one of them
    /// listening on a file nobody can reach. Exactly one bind may win each round.
    #[test]
    fn pends_racing_for_a_stale_socket_leave_exactly_one_listening() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let path = tmp.path().join("pend.sock");
        for round in 0..200 {
            drop(bind(&path, false).expect("binds"));
            assert!(path.exists(), "stale");
            let barrier = std::sync::Barrier::new(4);
            let won: Vec<_> = std::thread::scope(|s| {
                let racers: Vec<_> = (0..4)
                    .map(|_| {
                        s.spawn(|| {
                            barrier.wait();
                            bind(&path, false)
                        })
                    })
                    .collect();
                racers
                    .into_iter()
                    .filter_map(|r| r.join().expect("racer").ok())
                    .collect()
            });
            assert_eq!(won.len(), 1, "round {round}: {} binds won", won.len());
            drop(won);
        }
    }

    #[test]
    fn messages_name_the_path_and_say_the_reason_once() {
        let e = SocketError::Io {
            what: "listen on",
            path: PathBuf::from("/nowhere/pend.sock"),
            cause: io::Error::from(io::ErrorKind::NotFound),
        };
        assert!(
            std::error::Error::source(&e).is_none(),
            "the reason is in the message, not repeated"
        );
        assert!(
            e.to_string().starts_with("cannot listen on /nowhere/pend.sock: "),
            "{e}"
        );
    }
}
