//! Bad input: what the user gave is wrong (exit code 2).

use sim::scene::SceneError;

/// Bad input: an unknown scene or parameter, or an option value that cannot be used. The
/// message names the problem; `walker` exits with code 2.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The scene could not be loaded or built, or a parameter could not be set.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Any other bad option value, described.
    #[error("{0}")]
    Other(String),
}
