//! Why a scene could not be loaded or built ([`SceneError`]), and what a `[variant]` asks for
//! that its base cannot give ([`VariantError`]): each names what was wrong.

use super::expr::ExprError;
use crate::engine::integrators::IntegratorError;
use crate::engine::model::ModelError;

/// Why a scene could not be loaded or built. Each variant names what was wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// No such scene.
    #[error("unknown scene `{name}` (available: {available})")]
    UnknownScene {
        /// Asked for.
        name: String,
        /// Known names.
        available: String,
    },
    /// The file could not be read or parsed.
    #[error("scene file `{path}`: {message}")]
    File {
        /// Path or scene name.
        path: String,
        /// Parser message.
        message: String,
    },
    /// A parameter name the scene does not have.
    #[error("scene `{scene}` has no parameter `{name}` (parameters: {available})")]
    UnknownParameter {
        /// Scene.
        scene: String,
        /// Asked for.
        name: String,
        /// Known names.
        available: String,
    },
    /// A parameter value that is not a finite number.
    #[error("parameter `{name}`: `{value}` is not a finite number")]
    NotANumber {
        /// Parameter.
        name: String,
        /// Given text.
        value: String,
    },
    /// A parameter outside its physical range.
    #[error(
        "parameter `{name}` = {}{} is outside its allowed range [{}, {}]",
        short_number(*.value),
        unit_suffix(.unit),
        short_number(*.min),
        short_number(*.max)
    )]
    OutOfRange {
        /// Parameter.
        name: String,
        /// Value.
        value: f64,
        /// Unit.
        unit: String,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// An expression failed.
    #[error("{0}")]
    Expr(#[from] ExprError),
    /// A `[variant]` names something its base does not have.
    #[error("{0}")]
    Variant(#[from] VariantError),
    /// An expression gave NaN or infinity.
    #[error("`{what}` evaluates to {value}, not a finite number")]
    NonFinite {
        /// Where.
        what: String,
        /// The value.
        value: f64,
    },
    /// The model is not physical or inconsistent.
    #[error("model: {0}")]
    Model(#[from] ModelError),
    /// A reference to something undefined, or a bad keyword.
    #[error("{0}")]
    Invalid(String),
    /// An assignment ([`super::Scene::set_text`]) that is not `key=value`.
    #[error("`{text}`: expected key=value")]
    NotAnAssignment {
        /// The text given.
        text: String,
    },
    /// The `[integrator]` settings cannot run a stride.
    #[error("scene `{scene}` [integrator]: {error}")]
    Integrator {
        /// Scene.
        scene: String,
        /// What is wrong.
        error: IntegratorError,
    },
    /// Setting a parameter that acts on nothing of this walker.
    #[error("scene `{scene}`: parameter `{name}` acts on nothing of this walker (no expression uses it{}), so setting it would change nothing", variant_of.as_ref().map(|b| format!("; the variant of `{b}` removed or welded the bodies it belongs to")).unwrap_or_default())]
    UnusedParameter {
        /// Scene.
        scene: String,
        /// Parameter.
        name: String,
        /// The base scene of the variant, if the scene is one.
        variant_of: Option<String>,
    },
}

/// What a `[variant]` asks for that its base cannot give. Each names the link or parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VariantError {
    /// The variant's table has no `[variant]`.
    #[error("variant: missing [variant] table")]
    Missing,
    /// The base has no `[[link]]` array.
    #[error("base has no links")]
    NoLinks,
    /// `weld` or `remove` names a link the base does not have.
    #[error("variant: unknown link `{link}`")]
    UnknownLink {
        /// As named.
        link: String,
    },
    /// `[variant.joint.<link>]` names a link the base does not have.
    #[error("variant of `{base}`: [variant.joint.{link}]: no link `{link}` (links: {available})")]
    UnknownJoint {
        /// The base scene.
        base: String,
        /// As named.
        link: String,
        /// The links there are.
        available: String,
    },
    /// `[variant.joint.<link>]` on a weld (or a link the variant removes): no coordinate for a
    /// spring or damper to act on.
    #[error("variant of `{base}`: [variant.joint.{link}]: the link's joint is {why}, so a spring or damper has nothing to act on")]
    NoJoint {
        /// The base scene.
        base: String,
        /// The link.
        link: String,
        /// `a weld` or `removed by this variant`.
        why: &'static str,
    },
    /// `[variant.defaults]` names a parameter that neither the base nor the variant has.
    #[error(
        "variant of `{base}`: [variant.defaults]: no parameter `{name}` (parameters: {available})"
    )]
    UnknownParameter {
        /// The base scene.
        base: String,
        /// As named.
        name: String,
        /// The parameters there are.
        available: String,
    },
}

/// The unit after a value in a message: nothing for a dimensionless parameter (unit `1` or
/// empty), else a space and the unit.
fn unit_suffix(unit: &str) -> String {
    match unit {
        "" | "1" => String::new(),
        u => format!(" {u}"),
    }
}

/// `x` for a message: as Rust prints it between 1e-4 and 1e15 (and 0, ±∞), else in short
/// scientific form (`1e-300`, not three hundred digits).
pub fn short_number(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
