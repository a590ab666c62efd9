//! A hybrid multibody engine for passive dynamic walkers, after Wisse, Schwab & van der Linde
//! (2001), section 3: TMT equations of motion, Meijaard's integrator, Hermite event location,
//! impact equations, stride function, Newton-Raphson limit cycles and their stability.
//!
//! # From a scene to a gait, its eigenvalues and a continuation
//!
//! A walker is described by a scene file (docs/scenes.md is the format's reference; the
//! built-in scenes are `sim/scenes/*.toml`). Load one, find its gait (a fixed point of the
//! stride map) from the scene's guess, read the stride map's eigenvalues, and follow the gait
//! as a parameter changes:
//!
//! ```
//! use sim::analysis::continuation::sweep;
//! use sim::analysis::limit_cycle::NewtonSettings;
//! use sim::scene::Scene;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // Goswami's compass gait on its 0.0525 rad slope.
//! let scene = Scene::load("compass")?;
//! let setup = scene.setup()?;
//! let newton = NewtonSettings::default();
//! let gait = setup.find_gait(&newton)?;
//! println!("period {:.4} s", gait.stride.duration_s);
//! for z in &gait.eigenvalues {
//!     println!("λ = {:.6} {:+.6} i, |λ| = {:.6}", z.re, z.im, z.norm());
//! }
//! // The compass gait is stable at this slope.
//! assert!(gait.max_abs_eigenvalue() < 1.0);
//!
//! // The gait followed over three slopes, each point continued from the last.
//! let (points, _stability_changes) = sweep(&scene, "slope_rad", 0.0525, 0.0545, 3, &newton)?;
//! for p in &points {
//!     match &p.gait {
//!         Ok(g) => println!("slope {:.4} rad: max |λ| = {:.6}", p.value, g.max_abs_eigenvalue()),
//!         Err(e) => println!("slope {:.4} rad: no gait ({e})", p.value),
//!     }
//! }
//! assert_eq!(points.len(), 3);
//! # Ok(())
//! # }
//! ```
//!
//! # Where things are
//!
//! Five modules, one per concern, and a [`prelude`]:
//! - [`engine`]: the model and its equations — [`engine::model`] (links, joints, points),
//!   [`engine::kinematics`], [`engine::dynamics`] (the TMT equations of motion),
//!   [`engine::contact`] and [`engine::impact`] (constraints and the impact equations),
//!   [`engine::integrators`], [`engine::events`] and [`engine::hermite`] (event location); the
//!   walker: [`engine::walker`] (a model with its heel-strike, knee, fall and relabelling
//!   rules), [`engine::relabel`], [`engine::actuator`] and [`engine::control`] (the ankle reflex
//!   and controllers). The fast evaluations of special walkers ([`engine::PlanarTree`],
//!   [`engine::AxisTree`]) are chosen by the stride; their internals are the crate's own.
//! - [`stride`]: one stride of the hybrid map (one loop for every evaluation), the workspace
//!   repeated strides reuse, and [`stride::walk`] (many strides).
//! - [`analysis`]: [`analysis::limit_cycle`] (gaits by Newton's method),
//!   [`analysis::stability`], [`analysis::variational`] (exact stride Jacobians),
//!   [`analysis::continuation`] (following gaits and their bifurcations),
//!   [`analysis::homotopy`], [`analysis::census`], [`analysis::orbit_diagram`],
//!   [`analysis::stability_map`], [`analysis::tune`], [`analysis::accuracy`].
//! - [`scene`]: the TOML scene files (docs/scenes.md) and what they build.
//! - [`report`]: what the `walker` command prints, as data.

pub mod analysis;
pub mod engine;
pub mod prelude;
pub mod report;
pub mod scene;
pub mod stride;
