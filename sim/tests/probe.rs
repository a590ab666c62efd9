use sim::scene::Scene;
use nalgebra::DVector;
use sim::stride::StrideOptions;

#[test]
fn probe() {
    let scene = Scene::load("kneed2d").unwrap();
    let w = scene.build().unwrap();
    let v = DVector::from_vec(vec![0.2, -0.4, 0.0, -1.0, 0.5, 0.0]);
    let (q, qd) = w.unpack(&v);
    let mut wk = w.clone();
    wk.heel_strike.min_ahead_m = 10.0; // never strike
    wk.heel_strike.ignore_scuffing = true;
    let r = wk.stride(&q, &qd, StrideOptions{record:true});
    println!("{:?}", r.as_ref().err());
    let mut kin = sim::kinematics::Kinematics::new(&w.model);
    let foot = w.model.point_index("swing_foot").unwrap();
    if let Err(_) = r { }
    // re-run with recording until failure using walk
    let walk = wk.walk(&q, &qd, 1, true);
    for s in walk.path.iter().step_by(3) {
        kin.update(&w.model, &s.q, &s.qd);
        let p = kin.point_position(&w.model, foot);
        println!("t={:.3} q={:.3?} foot=({:.3},{:.4})", s.time_s, s.q.as_slice(), p.x, p.y);
    }
}
