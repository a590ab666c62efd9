//! What is computed from strides: gaits (fixed points of the stride map) and their stability,
//! exact stride Jacobians, homotopies and continuation of gaits through their bifurcations, the
//! census of gaits, orbit diagrams, stability maps, tuning, design optimisation (CMA-ES), and
//! speed against error.

pub mod accuracy;
pub mod census;
pub mod continuation;
pub mod gait_sensitivity;
pub mod homotopy;
pub mod limit_cycle;
pub mod optimize;
pub mod orbit_diagram;
pub mod quantity;
pub mod robustness;
pub mod solver_options;
pub mod stability;
pub mod stability_map;
pub mod tune;
pub mod variational;
pub mod walk_start;
