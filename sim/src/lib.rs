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
//! use sim::continuation::sweep;
//! use sim::limit_cycle::NewtonSettings;
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
//! - The model and its equations: [`model`] (links, joints, points), [`kinematics`],
//!   [`dynamics`] (the TMT equations of motion), [`contact`] and [`impact`] (constraints and the
//!   impact equations), [`integrators`], [`events`] and [`hermite`] (event location),
//!   [`planar`] and [`axis_tree`] (fast evaluations of special walkers), [`singular_limit`]
//!   (infinitesimal masses), [`math`].
//! - The walker and its stride: [`walker`] (a model with its heel-strike, knee, fall and
//!   relabelling rules), [`relabel`], [`actuator`] and [`control`] (the ankle reflex and
//!   controllers), [`hybrid`], [`stride`] (one stride of the hybrid map), [`walk`] (many).
//! - Analysis: [`limit_cycle`] (gaits by Newton's method), [`stability`], [`variational`]
//!   (exact stride Jacobians), [`continuation`] (following gaits and their bifurcations),
//!   [`census`], [`orbit_diagram`], [`stability_map`], [`tune`], [`accuracy`].
//! - Scenes and reports: [`scene`] (the TOML scene files), [`report`] (what the `walker`
//!   command prints, as data).

pub mod accuracy;
pub mod actuator;
pub mod axis_tree;
pub mod census;
pub mod contact;
pub mod continuation;
pub mod control;
pub mod dynamics;
pub mod events;
pub mod hermite;
pub mod homotopy;
pub mod hybrid;
pub mod impact;
pub mod integrators;
pub mod kinematics;
pub mod limit_cycle;
pub mod math;
pub mod model;
pub mod orbit_diagram;
pub mod planar;
pub mod relabel;
pub mod report;
pub mod scene;
pub mod singular_limit;
pub mod stability;
pub mod stability_map;
pub mod stride;
pub mod tune;
pub mod variational;
pub mod walk;
pub mod walker;
