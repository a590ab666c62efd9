//! The floor a walk goes over: one plane (the slope), a step up or down at a chosen heel
//! strike, or a rough floor whose level changes at every heel strike by a seeded random draw.
//! Each stride ends on a floor some height above its stance foot's
//! ([`super::StrideOptions::floor_step_m`]); the floor stays at the new level.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;

/// A floor. Heights are measured along the floor's normal (the slope's), up positive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Floor {
    /// One plane.
    #[default]
    Plane,
    /// A step of `height_m` (up > 0, down < 0) where the swing foot lands at heel strike
    /// `at_heel_strike` (counted from 1); the floor stays at the new level.
    Step {
        /// The heel strike that lands on the step (1 is the first).
        at_heel_strike: usize,
        /// Its height \[m\].
        height_m: f64,
    },
    /// At every heel strike the floor's level changes by a draw from a normal distribution of
    /// standard deviation `sigma_m` (mean 0), the draws reproducible from `seed` (ChaCha8).
    Rough {
        /// Standard deviation of each change \[m\].
        sigma_m: f64,
        /// The draws' seed.
        seed: u64,
    },
}

/// Why a floor's text form is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "floor `{text}`: {reason} (expected plane, step:at=K,height_m=H or rough:sigma_m=S[,seed=N])"
)]
pub struct FloorError {
    /// The text given.
    pub text: String,
    /// What is wrong with it.
    pub reason: String,
}

impl std::str::FromStr for Floor {
    type Err = FloorError;

    fn from_str(text: &str) -> Result<Self, FloorError> {
        let bad = |reason: String| FloorError {
            text: text.to_owned(),
            reason,
        };
        let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
        let mut at = None;
        let mut height = None;
        let mut sigma = None;
        let mut seed = None;
        for part in rest.split(',').filter(|p| !p.is_empty()) {
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| bad(format!("`{part}` is not KEY=VALUE")))?;
            let slot = match (kind, k) {
                ("step", "at") => &mut at,
                ("step", "height_m") => &mut height,
                ("rough", "sigma_m") => &mut sigma,
                ("rough", "seed") => &mut seed,
                _ => return Err(bad(format!("no key `{k}` for a {kind} floor"))),
            };
            if slot.replace(v).is_some() {
                return Err(bad(format!("`{k}` given twice")));
            }
        }
        let number = |k: &str, v: Option<&str>| -> Result<f64, FloorError> {
            let v = v.ok_or_else(|| bad(format!("`{k}` is missing")))?;
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("{k} = `{v}` is not a finite number")))
        };
        match kind {
            "plane" if rest.is_empty() => Ok(Floor::Plane),
            "step" => {
                let at = at.ok_or_else(|| bad("`at` is missing".into()))?;
                let at_heel_strike = at
                    .parse::<usize>()
                    .ok()
                    .filter(|k| *k >= 1)
                    .ok_or_else(|| bad(format!("at = `{at}` is not a heel strike 1, 2, ...")))?;
                Ok(Floor::Step {
                    at_heel_strike,
                    height_m: number("height_m", height)?,
                })
            }
            "rough" => {
                let sigma_m = number("sigma_m", sigma)?;
                if sigma_m < 0.0 {
                    return Err(bad(format!("sigma_m = {sigma_m} is negative")));
                }
                let seed = match seed {
                    None => 0,
                    Some(s) => s
                        .parse::<u64>()
                        .map_err(|_| bad(format!("seed = `{s}` is not a whole number")))?,
                };
                Ok(Floor::Rough { sigma_m, seed })
            }
            _ => Err(bad(format!("unknown floor `{kind}`"))),
        }
    }
}

impl Floor {
    /// The floor in words for a report; `None` for one plane.
    pub fn describe(&self) -> Option<String> {
        match *self {
            Floor::Plane => None,
            Floor::Step {
                at_heel_strike,
                height_m,
            } => Some(format!(
                "a step of {height_m} m (up positive, along the slope's normal) at heel strike \
                 {at_heel_strike}"
            )),
            Floor::Rough { sigma_m, seed } => Some(format!(
                "rough, the level changing by a normal draw of sd {sigma_m} m at every heel \
                 strike (seed {seed})"
            )),
        }
    }

    /// The heights its strides end on, in order.
    pub fn heights(&self) -> FloorHeights {
        let rough = match *self {
            Floor::Rough { sigma_m, seed } => Normal::new(0.0, sigma_m)
                .ok()
                .map(|n| (ChaCha8Rng::seed_from_u64(seed), n)),
            _ => None,
        };
        FloorHeights {
            floor: *self,
            rough,
            strides: 0,
        }
    }
}

/// The floor steps of a walk's strides, one per stride in order ([`Floor::heights`]).
#[derive(Clone, Debug)]
pub struct FloorHeights {
    floor: Floor,
    rough: Option<(ChaCha8Rng, Normal<f64>)>,
    strides: usize,
}

impl FloorHeights {
    /// The floor the next stride ends on, above its stance foot's \[m\].
    pub fn next_step_m(&mut self) -> f64 {
        self.strides += 1;
        match self.floor {
            Floor::Plane => 0.0,
            Floor::Step {
                at_heel_strike,
                height_m,
            } => {
                if self.strides == at_heel_strike {
                    height_m
                } else {
                    0.0
                }
            }
            Floor::Rough { .. } => self
                .rough
                .as_mut()
                .map_or(0.0, |(rng, normal)| normal.sample(rng)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floors_parse_and_give_their_steps() {
        let f: Floor = "step:at=3,height_m=-0.02".parse().unwrap();
        let mut h = f.heights();
        let steps: Vec<f64> = (0..5).map(|_| h.next_step_m()).collect();
        assert_eq!(steps, vec![0.0, 0.0, -0.02, 0.0, 0.0]);
        let r: Floor = "rough:sigma_m=0.01,seed=7".parse().unwrap();
        let draws = |f: Floor| {
            let mut h = f.heights();
            (0..4000).map(|_| h.next_step_m()).collect::<Vec<f64>>()
        };
        let (a, b) = (draws(r), draws(r));
        assert_eq!(a, b, "reproducible from the seed");
        assert_ne!(a, draws("rough:sigma_m=0.01,seed=8".parse().unwrap()));
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        let sd = (a.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / a.len() as f64).sqrt();
        // 4000 draws: the mean within 4 standard errors, the deviation within 5 %
        assert!(mean.abs() < 4.0 * 0.01 / 4000f64.sqrt(), "{mean}");
        assert!((sd / 0.01 - 1.0).abs() < 0.05, "{sd}");
        assert_eq!("plane".parse::<Floor>().unwrap(), Floor::Plane);
        for bad in [
            "step:height_m=0.1",
            "step:at=0,height_m=0.1",
            "step:at=1,height_m=inf",
            "rough:sigma_m=-1",
            "rough:sigma_m=0.1,seed=x",
            "rough:sigma_m=0.1,sigma_m=0.2",
            "bumpy",
            "step:at=1,height=0.1",
        ] {
            let e = bad.parse::<Floor>().unwrap_err().to_string();
            assert!(e.contains(bad), "{e}");
        }
    }
}
