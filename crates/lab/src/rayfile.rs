//! The ray-file format shared with other libraries: little endian, a `u64` count, then
//! `count` rays of 8 `f32`: `ox oy oz tmin dx dy dz tmax`.

use std::io::Read;
use std::path::Path;

use raylab_core::{Ray, Vec3};

#[derive(Debug, thiserror::Error)]
pub enum RayFileError {
    #[error("{path}: {message}")]
    Invalid { path: String, message: String },
}

fn err(path: &Path, message: impl Into<String>) -> RayFileError {
    RayFileError::Invalid { path: path.display().to_string(), message: message.into() }
}

pub fn write(path: &Path, rays: &[Ray]) -> Result<(), RayFileError> {
    let mut bytes = Vec::with_capacity(8 + rays.len() * 32);
    bytes.extend_from_slice(&(rays.len() as u64).to_le_bytes());
    for r in rays {
        for v in [r.origin.x, r.origin.y, r.origin.z, r.t_min, r.dir.x, r.dir.y, r.dir.z, r.t_max] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    raylab_render::film::atomic::write_atomic(path, &bytes).map_err(|e| err(path, format!("cannot write: {e}")))
}

pub fn read(path: &Path) -> Result<Vec<Ray>, RayFileError> {
    // Only a regular file has an end: `/dev/zero` or a folder would read until memory is
    // exhausted, or fail with a puzzling message.
    let meta = std::fs::metadata(path).map_err(|e| err(path, format!("cannot open: {e}")))?;
    if !meta.is_file() {
        return Err(err(path, "is not a regular file (a folder or a device)"));
    }
    raylab_render::memory_guard::check("reading it", Some(meta.len())).map_err(|e| err(path, e))?;
    let mut f = std::fs::File::open(path).map_err(|e| err(path, format!("cannot open: {e}")))?;
    let mut bytes = Vec::new();
    f.read_to_end(&mut bytes).map_err(|e| err(path, format!("cannot read: {e}")))?;
    if bytes.len() < 8 {
        return Err(err(path, format!("too short for a ray file ({} bytes; the header alone is 8)", bytes.len())));
    }
    let count = u64::from_le_bytes(bytes[..8].try_into().unwrap());
    let body = &bytes[8..];
    if count.checked_mul(32) != Some(body.len() as u64) {
        return Err(err(path, format!("the header says {count} rays ({} bytes) but {} bytes follow", count.saturating_mul(32), body.len())));
    }
    let mut rays = Vec::with_capacity(count as usize);
    for (k, rec) in body.chunks_exact(32).enumerate() {
        let f: Vec<f32> = rec.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
        let ray = Ray { origin: Vec3::new(f[0], f[1], f[2]), t_min: f[3], dir: Vec3::new(f[4], f[5], f[6]), t_max: f[7] };
        if !ray.origin.is_finite() || !ray.dir.is_finite() || ray.dir == Vec3::ZERO || ray.t_min.is_nan() || ray.t_max.is_nan() {
            return Err(err(path, format!("ray {k} is not valid (non-finite values or a zero direction)")));
        }
        rays.push(ray);
    }
    Ok(rays)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_errors() {
        let dir = std::env::temp_dir().join(format!("raylab-rayfile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("rays.bin");
        let rays = vec![Ray::segment(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, -1.0), 0.0, 10.0), Ray::new(Vec3::ZERO, Vec3::X)];
        write(&p, &rays).unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().len(), 8 + 2 * 32);
        assert_eq!(read(&p).unwrap(), rays);
        std::fs::write(&p, [1u8, 0, 0, 0, 0, 0, 0, 0, 0, 0]).unwrap();
        assert_eq!(read(&p).unwrap_err().to_string(), format!("{}: the header says 1 rays (32 bytes) but 2 bytes follow", p.display()));
        std::fs::write(&p, [1u8, 2]).unwrap();
        assert_eq!(read(&p).unwrap_err().to_string(), format!("{}: too short for a ray file (2 bytes; the header alone is 8)", p.display()));
        assert_eq!(read(&dir).unwrap_err().to_string(), format!("{}: is not a regular file (a folder or a device)", dir.display()));
        #[cfg(unix)]
        assert_eq!(read(Path::new("/dev/zero")).unwrap_err().to_string(), "/dev/zero: is not a regular file (a folder or a device)");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
