//! Stanford `.ply` files: not read yet.

use super::{MeshData, MeshError};

/// Refuses every PLY file with a clear message (see the module line).
pub(super) fn parse(_bytes: &[u8], _budget: usize) -> Result<MeshData, MeshError> {
    Err(MeshError::whole(
        "PLY files are not read yet: convert it to `.obj`",
    ))
}
