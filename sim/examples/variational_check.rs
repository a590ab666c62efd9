//! The variational stride Jacobian against the central-difference one, with timings
//! (`cargo run --release -p sim --example variational_check -- compass kneed2d wisse3d`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nalgebra::DMatrix;
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};

fn moduli(j: &DMatrix<f64>) -> Vec<f64> {
    let mut m: Vec<f64> = j
        .clone()
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .collect();
    m.sort_by(|a, b| b.total_cmp(a));
    m.truncate(6);
    m
}

fn main() {
    for name in std::env::args().skip(1) {
        let setup = sim::scene::Scene::load(&name).unwrap().setup().unwrap();
        let newton = NewtonSettings::default();
        let search = GaitSearch::new(&setup.walker, &setup.settings, &newton);
        let g = search.find_from_guess(&setup.guess).unwrap();
        let s = search.stride_map(&g.fixed_point).unwrap().0;
        let t0 = std::time::Instant::now();
        let fd = search.stride_jacobian(&g.fixed_point, &s).unwrap();
        let t_fd = t0.elapsed().as_secs_f64();
        let t0 = std::time::Instant::now();
        let var = sim::analysis::variational::stride_jacobian(
            &setup.walker,
            &g.fixed_point,
            &setup.settings,
        );
        let t_var = t0.elapsed().as_secs_f64();
        match var {
            Ok((jv, _)) => {
                println!(
                    "{name}: max |J_var - J_fd| = {:.2e} (|J| {:.2e}); {:.1} ms variational, {:.1} ms central differences",
                    (&jv - &fd).amax(),
                    fd.amax(),
                    t_var * 1e3,
                    t_fd * 1e3
                );
                println!("  variational {:?}", moduli(&jv));
                println!("  central     {:?}", moduli(&fd));
            }
            Err(e) => println!("{name}: {e}"),
        }
    }
}
