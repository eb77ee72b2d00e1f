//! [`IntoMat4`]: the matrices the API accepts — `glam::Mat4` (`ignis::glam`) or plain
//! column-major arrays, as any other math library's `to_cols_array` gives them.

use glam::Mat4;

/// A 4×4 matrix the API accepts: a `glam::Mat4` of ignis's glam (`ignis::glam`), or a
/// column-major `[[f32; 4]; 4]` or `[f32; 16]` (a host on another glam version, or
/// another math library, passes `m.to_cols_array_2d()`).
pub trait IntoMat4 {
    /// The matrix as ignis's `Mat4`.
    fn into_mat4(self) -> Mat4;
}

impl IntoMat4 for Mat4 {
    fn into_mat4(self) -> Mat4 {
        self
    }
}

impl IntoMat4 for &Mat4 {
    fn into_mat4(self) -> Mat4 {
        *self
    }
}

impl IntoMat4 for [[f32; 4]; 4] {
    fn into_mat4(self) -> Mat4 {
        Mat4::from_cols_array_2d(&self)
    }
}

impl IntoMat4 for [f32; 16] {
    fn into_mat4(self) -> Mat4 {
        Mat4::from_cols_array(&self)
    }
}
