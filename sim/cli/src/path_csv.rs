//! `walker walk --out`: the trajectory as CSV, written row by row as the walk's strides
//! complete, so memory does not grow with the walk or the integrator's step.

use sim::engine::walker::Walker;
use sim::stride::walk::PathSample;
use std::fs::File;
use std::io::{BufWriter, Write};

/// A CSV of path samples: step, time, coordinates, rates and the hip-axle centre in the floor
/// frame, one row per integrator sample. The first write error is kept (and the rest of the
/// rows skipped) for [`PathCsv::finish`].
pub struct PathCsv {
    file: BufWriter<File>,
    error: Option<std::io::Error>,
}

impl PathCsv {
    /// Writes the header for `walker`'s coordinates.
    pub fn new(file: File, walker: &Walker) -> Self {
        let mut csv = PathCsv {
            file: BufWriter::new(file),
            error: None,
        };
        let coords: Vec<&str> = walker
            .model()
            .coordinates
            .iter()
            .map(|c| c.name.as_str())
            .collect();
        let mut header = String::from("step,time_s");
        for c in &coords {
            header.push(',');
            header.push_str(c);
        }
        for c in &coords {
            header.push(',');
            header.push_str(c);
            header.push_str("_dot");
        }
        header.push_str(",hip_x_m,hip_y_m,hip_z_m");
        csv.attempt(|f| writeln!(f, "{header}"));
        csv
    }

    /// Appends `s`'s row.
    pub fn row(&mut self, s: &PathSample) {
        self.attempt(|f| {
            write!(f, "{},{}", s.step, s.t_walk_s)?;
            for v in s.q.iter().chain(s.qd.iter()) {
                write!(f, ",{v}")?;
            }
            writeln!(
                f,
                ",{},{},{}",
                s.hip_floor_m.x, s.hip_floor_m.y, s.hip_floor_m.z
            )
        });
    }

    fn attempt(&mut self, w: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>) {
        if self.error.is_none() {
            if let Err(e) = w(&mut self.file) {
                self.error = Some(e);
            }
        }
    }

    /// Flushes; the first error of any write.
    ///
    /// # Errors
    /// The first write or flush error.
    pub fn finish(mut self) -> std::io::Result<()> {
        match self.error.take() {
            Some(e) => Err(e),
            None => self.file.flush(),
        }
    }
}
