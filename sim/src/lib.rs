//! A hybrid multibody engine for passive dynamic walkers, after Wisse, Schwab & van der Linde
//! (2001), section 3: TMT equations of motion, Meijaard's integrator, Hermite event location,
//! impact equations, stride function, Newton-Raphson limit cycles and their stability.

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
