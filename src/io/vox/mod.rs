//! MagicaVoxel `.vox` loading and saving.
//!
//! Loading runs in three steps: [`validate`] walks the raw chunk structure and
//! rejects anything that could make `dot_vox` panic, recurse without bound or
//! allocate far more than the file holds; `dot_vox::load_bytes` then parses the
//! file (inside `catch_unwind`); [`scene`] walks the scene graph and
//! [`transform`] places each model voxel the way MagicaVoxel shows it. Saving writes a version-200 file with a
//! small scene graph, splitting scenes wider than 256 voxels into several models.
//!
//! Axes: MagicaVoxel is z up, octovox is y up, both right-handed. A voxel at
//! MagicaVoxel scene position (x, y, z) (after its scene-graph transforms) is
//! octovox world voxel (x, z, −y). `docs/vox.md` has the details.

mod chunk;
mod load;
mod save;
mod stored;
mod validate;

use std::path::PathBuf;

pub use load::{VoxMeta, load_vox, load_vox_file, load_vox_objects, load_vox_scene, load_vox_scene_file};
pub use save::{encode_objects, encode_vox, save_objects, save_tree, save_vox};

/// Most voxels one load may produce (after scene-graph instancing).
pub const MAX_VOXELS: usize = 1 << 26;

/// Largest `.vox` file octovox reads.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

pub use crate::scene::graph::{MAX_INSTANCES, MAX_NODE_VISITS};

/// Why a `.vox` file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum VoxError {
    /// The file could not be opened or read.
    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: std::io::Error },
    /// The file (or its temporary sibling) could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
    /// The file is larger than [`MAX_FILE_BYTES`].
    #[error("{} is larger than {MAX_FILE_BYTES} bytes, the most octovox reads from a .vox file", path.display())]
    FileTooLarge { path: PathBuf },
    /// A device, socket or folder.
    #[error("{} is not a regular file (a device, socket or folder)", path.display())]
    NotRegular { path: PathBuf },
    /// The first four bytes are not `VOX `.
    #[error("not a .vox file (missing 'VOX ' magic)")]
    NotVox,
    /// A version other than 150 or 200.
    #[error("unsupported .vox version {0} (octovox reads versions 150 and 200)")]
    UnsupportedVersion(u32),
    /// The file ends before its header or its MAIN chunk does.
    #[error("file is truncated: {0}")]
    Truncated(String),
    /// A chunk whose header or content is inconsistent, e.g.
    /// "chunk XYZI at byte 1234 claims 2147483648 voxels but holds 40 bytes".
    #[error("chunk {id} at byte {offset} {problem}")]
    BadChunk { id: String, offset: usize, problem: String },
    /// A scene-graph node reachable from itself.
    #[error("scene graph cycle at node {0}")]
    SceneCycle(u32),
    /// Any other scene-graph problem: a missing node, a model id out of
    /// range, a malformed transform.
    #[error("scene graph: {0}")]
    BadSceneGraph(String),
    /// `--frame` beyond the models of a file without a scene graph.
    #[error("frame {requested} requested but file has {models} model{}", plural(*models))]
    FrameOutOfRange { requested: usize, models: usize },
    /// The scene would produce more than [`MAX_VOXELS`] voxels.
    #[error("the scene holds more than {limit} voxels (at least {found}); octovox loads at most {limit}")]
    TooManyVoxels { limit: usize, found: usize },
    /// `dot_vox` rejected bytes the pre-pass accepted.
    #[error("dot_vox could not parse the file: {0}")]
    Parser(&'static str),
    /// `dot_vox` panicked; the panic was caught.
    #[error("dot_vox panicked while parsing the file: {0}")]
    ParserPanic(String),
    /// `dot_vox`'s result disagrees with the pre-pass (a bug in one of them).
    #[error("internal inconsistency while loading: {0}")]
    Inconsistent(String),
    /// Loading would take more memory than the budget allows.
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
    /// The voxels cannot be written as a `.vox` file.
    #[error("cannot save: {0}")]
    Unsavable(String),
}

impl From<crate::scene::graph::GraphError> for VoxError {
    fn from(e: crate::scene::graph::GraphError) -> VoxError {
        use crate::scene::graph::GraphError;
        match e {
            GraphError::Cycle(node) => VoxError::SceneCycle(node),
            GraphError::Bad(problem) => VoxError::BadSceneGraph(problem),
            late @ GraphError::FrameTooLate(_) => VoxError::BadSceneGraph(late.to_string()),
            GraphError::TooManyVoxels { limit, found } => VoxError::TooManyVoxels { limit, found },
            GraphError::OverBudget(over) => VoxError::OverBudget(over),
        }
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}
