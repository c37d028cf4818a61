//! The library's error type.
//!
//! Every error that input can cause says where it happened: the file (and line, when the parser
//! knows it) and what is wrong, in lowercase and without a trailing period, so that `main` can
//! print the chain as `error: <path>:<line>: <problem>`.

use std::fmt;
use std::path::{Path, PathBuf};

/// Result alias used throughout tessera.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong while loading a scene, rendering or writing an image.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A scene file is malformed or refers to something that does not exist.
    #[error("{}{}: {msg}", path.display(), Line(*line))]
    Scene {
        /// The scene file.
        path: PathBuf,
        /// 1-based line, when known.
        line: Option<usize>,
        /// What is wrong.
        msg: String,
    },
    /// A mesh file (OBJ, glTF) is malformed or holds unusable geometry.
    #[error("{}: {msg}", path.display())]
    Mesh {
        /// The mesh file.
        path: PathBuf,
        /// What is wrong.
        msg: String,
    },
    /// An image file could not be decoded or encoded.
    #[error("{}: {msg}", path.display())]
    Image {
        /// The image file.
        path: PathBuf,
        /// What is wrong.
        msg: String,
    },
    /// An error in a file that a scene item refers to, with the scene file and the item.
    #[error("{}: {item}: {source}", scene.display())]
    InScene {
        /// The scene file.
        scene: PathBuf,
        /// The item of the scene (`textures.checker`, `shapes[2]`).
        item: String,
        /// What went wrong with it.
        source: Box<Error>,
    },
    /// A third-party parser failed in a way it should have reported as an error (a panic,
    /// caught by [`guard_parser`]): the file is malformed in a way tessera does not yet check.
    #[error("{}: malformed file (the parser failed: {msg})", path.display())]
    Parser {
        /// The file being parsed.
        path: PathBuf,
        /// The parser's panic message and where it happened.
        msg: String,
    },
    /// A parameter is out of its valid range (a resolution, a sample count, a roughness...).
    #[error("{what}: {msg}")]
    Param {
        /// The parameter, named as the user wrote it (`spp`, `materials.metal.alpha_u`).
        what: String,
        /// What is wrong and what is allowed.
        msg: String,
    },
}

/// Formats an optional line number as `:N`.
struct Line(Option<usize>);

impl fmt::Display for Line {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(line) => write!(f, ":{line}"),
            None => Ok(()),
        }
    }
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: impl AsRef<Path>, source: std::io::Error) -> Self {
        Error::Io { path: path.as_ref().to_path_buf(), source }
    }

    /// A scene error without a line number.
    pub fn scene(path: impl AsRef<Path>, msg: impl Into<String>) -> Self {
        Error::Scene { path: path.as_ref().to_path_buf(), line: None, msg: msg.into() }
    }

    /// A mesh error.
    pub fn mesh(path: impl AsRef<Path>, msg: impl Into<String>) -> Self {
        Error::Mesh { path: path.as_ref().to_path_buf(), msg: msg.into() }
    }

    /// An image error.
    pub fn image(path: impl AsRef<Path>, msg: impl Into<String>) -> Self {
        Error::Image { path: path.as_ref().to_path_buf(), msg: msg.into() }
    }

    /// Attach the scene file and item that led to this error.
    pub fn in_scene(self, scene: impl AsRef<Path>, item: impl Into<String>) -> Self {
        Error::InScene { scene: scene.as_ref().to_path_buf(), item: item.into(), source: Box::new(self) }
    }

    /// A parameter error.
    pub fn param(what: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::Param { what: what.into(), msg: msg.into() }
    }
}

thread_local! {
    /// Set while [`guard_parser`] runs a parser on this thread: its panics are caught, so the
    /// panic hook keeps their message for the error instead of printing it.
    static GUARDED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    static CAUGHT: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Run a third-party parser (glTF, OBJ, image decoders), turning a panic inside it into an
/// error naming `path`. This is the last line of defence only: tessera validates what it
/// hands to these parsers so that they do not panic; a panic that gets here is a gap in that
/// validation, reported as an error rather than a crash.
pub fn guard_parser<T>(path: &Path, parse: impl FnOnce() -> Result<T>) -> Result<T> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if GUARDED.get() {
                let message = info
                    .payload()
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| info.payload().downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "(no message)".into());
                let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
                CAUGHT.set(Some(format!("{message}{at}")));
            } else {
                previous(info);
            }
        }));
    });
    let outer = GUARDED.replace(true);
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse));
    GUARDED.set(outer);
    result.unwrap_or_else(|_| {
        let message = CAUGHT.take().unwrap_or_default();
        Err(Error::Parser { path: path.to_path_buf(), msg: message })
    })
}
