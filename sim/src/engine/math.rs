//! Small rotation helpers shared by kinematics, relabelling and impacts.

use nalgebra::{Matrix3, RealField, Vector3};

/// Rotation matrix for a rotation of `angle_rad` about the unit vector `axis` (Rodrigues);
/// generic over the scalar so that dual numbers carry derivatives through it.
pub fn rotation_about<T: RealField + Copy>(axis: &Vector3<f64>, angle_rad: T) -> Matrix3<T> {
    let (s, c) = angle_rad.sin_cos();
    let t = T::one() - c;
    let (x, y, z): (T, T, T) = (
        nalgebra::convert(axis.x),
        nalgebra::convert(axis.y),
        nalgebra::convert(axis.z),
    );
    // R = c I + s [k]× + (1 − c) k kᵀ, written out.
    Matrix3::new(
        c + t * x * x,
        t * x * y - s * z,
        t * x * z + s * y,
        t * x * y + s * z,
        c + t * y * y,
        t * y * z - s * x,
        t * x * z - s * y,
        t * y * z + s * x,
        c + t * z * z,
    )
}

/// Small-angle orientation error `e` such that `R_target ≈ exp([e]×) R_actual` (world frame).
pub fn orientation_error<T: RealField + Copy>(
    r_target: &Matrix3<T>,
    r_actual: &Matrix3<T>,
) -> Vector3<T> {
    let d = r_target * r_actual.transpose();
    let a = (d - d.transpose()) * nalgebra::convert::<f64, T>(0.5);
    Vector3::new(a[(2, 1)], a[(0, 2)], a[(1, 0)])
}

/// The reflection about the sagittal plane (z → −z) in the world frame.
pub fn sagittal_reflection() -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_about_z_turns_x_toward_y() {
        let r = rotation_about(&Vector3::z(), std::f64::consts::FRAC_PI_2);
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
    }

    /// The cross-product matrix: `skew(a) * b == a.cross(b)`.
    fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
    }

    #[test]
    fn rotation_about_matches_rodrigues_with_matrices() {
        let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
        let k = skew(&axis);
        let a: f64 = 0.7;
        let expected = Matrix3::identity() + k * a.sin() + k * k * (1.0 - a.cos());
        assert!((rotation_about(&axis, a) - expected).amax() < 1e-15);
    }

    #[test]
    fn orientation_error_recovers_small_rotation() {
        let axis = Vector3::new(1.0, 2.0, -0.5).normalize();
        let r = rotation_about(&axis, 0.3);
        let dr = rotation_about(&axis, 1e-6);
        let e = orientation_error(&(dr * r), &r);
        assert!((e - axis * 1e-6).norm() < 1e-15);
    }
}
