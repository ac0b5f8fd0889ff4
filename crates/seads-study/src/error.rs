//! The study library's error: what went wrong, with the error that caused it kept as its source.

/// A boxed error from below (I/O, JSON, TOML, plotting).
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// What can go wrong in a study.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// Input that cannot be used as given (a manifest, an index, a choice of runs): the user's
    /// to fix; the command line makes it exit code 2.
    #[error("{0}")]
    Invalid(String),
    /// Something the study needs does not hold (a run without the files it should have, a
    /// sweep changed since planning), said in a sentence.
    #[error("{0}")]
    Failed(String),
    /// Another error that, here, is the user's input to fix (exit code 2 on the command line).
    #[error(transparent)]
    Input(Box<StudyError>),
    /// Reading, writing or parsing a file or folder failed; `what` says which and what for.
    #[error("{what}")]
    File {
        /// What was being done, naming the path.
        what: String,
        /// Why it failed.
        #[source]
        source: BoxError,
    },
    /// The evaluation cannot be played in the agent's environment (input the user must fix).
    #[error(transparent)]
    Environment(seads_embodiment::EnvError),
    /// A file system call failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// JSON could not be written or read.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// TOML could not be read.
    #[error(transparent)]
    TomlRead(#[from] toml::de::Error),
    /// TOML could not be written.
    #[error(transparent)]
    TomlWrite(#[from] toml::ser::Error),
    /// Another task holds the run: the caller may wait or leave it to that task.
    #[error(transparent)]
    Taken(#[from] Taken),
    /// A run directory could not be read or written.
    #[error(transparent)]
    Run(#[from] seads_run::RunError),
    /// Drawing a figure failed.
    #[error("drawing a figure: {0}")]
    Plot(String),
}

/// `Result` with [`StudyError`].
pub type Result<T, E = StudyError> = std::result::Result<T, E>;

impl StudyError {
    /// An [`Invalid`](Self::Invalid) error from a message.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid(message.into())
    }

    /// A [`Failed`](Self::Failed) error from a message.
    pub fn failed(message: impl Into<String>) -> Self {
        Self::Failed(message.into())
    }

    /// A [`File`](Self::File) error: `what` was being done when `source` happened.
    pub fn file(what: impl Into<String>, source: impl Into<BoxError>) -> Self {
        Self::File {
            what: what.into(),
            source: source.into(),
        }
    }

    /// Whether the error is the user's input (exit code 2 on the command line).
    pub fn is_invalid(&self) -> bool {
        matches!(
            self,
            Self::Invalid(_) | Self::Input(_) | Self::Environment(_)
        )
    }

    /// This error as the user's input to fix: how a report treats inputs that are not sweeps or
    /// runs, or runs it cannot group.
    pub fn into_invalid(self) -> Self {
        if self.is_invalid() {
            self
        } else {
            Self::Input(Box::new(self))
        }
    }
}

/// Adds what was being done to an error from below, keeping it as the source.
pub trait Context<T> {
    /// Turns the error into a [`StudyError::File`] described by `what()`.
    fn doing(self, what: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: Into<BoxError>> Context<T> for std::result::Result<T, E> {
    fn doing(self, what: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| StudyError::file(what(), e))
    }
}

/// Returns early with a [`StudyError::Failed`] whose message is formatted as by `format!`.
macro_rules! fail {
    ($($arg:tt)*) => {
        return Err($crate::StudyError::Failed(format!($($arg)*)))
    };
}

/// A [`StudyError::Failed`] whose message is formatted as by `format!`.
macro_rules! failure {
    ($($arg:tt)*) => {
        $crate::StudyError::Failed(format!($($arg)*))
    };
}

pub(crate) use {fail, failure};

/// The error of a claim on a run that another task holds.
#[derive(Debug)]
pub struct Taken(pub std::path::PathBuf);

impl std::fmt::Display for Taken {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} is already being trained by another task",
            self.0.display()
        )
    }
}

impl std::error::Error for Taken {}
