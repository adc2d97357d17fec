//! The JSON scene format: types, parsing with precise error locations, validation, and
//! building a [`tribo::World`] from a scene.
//!
//! The field reference (units and defaults) is in `docs/scene-format.md`; the JSON Schema
//! in `docs/scene.schema.json`. Every field that may be left out has a default. Errors name
//! the place: the JSON path (`bodies[3].shapes[0].radius`) and the line:column.

use crate::locate::locate_path;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;
use tribo::{
    BodyDef, BodyId, BodyType, Capsule, ChainSegment, Circle, CombineRule, Filter, Material, Polygon, RevoluteJointDef,
    Segment, Shape, ShapeDef, Vec2, World, WorldDef,
};

/// A scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// One line saying what the scene shows (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Gravity [m/s²]. Default [0, −9.81].
    #[serde(default = "default_gravity")]
    pub gravity: [f32; 2],
    /// Step length [s]. Default 1/60.
    #[serde(default = "default_dt")]
    pub dt: f32,
    /// Substeps per step. Default 4.
    #[serde(default = "default_substeps")]
    pub substeps: u32,
    /// Steps to run. Default 600.
    #[serde(default = "default_steps")]
    pub steps: u32,
    /// Whether resting bodies may fall asleep. Default true.
    #[serde(default = "default_true")]
    pub enable_sleep: bool,
    /// Named materials, referenced by shapes.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// The bodies, in creation order.
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    /// The joints, created after the bodies, in this order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointSpec>,
}

fn default_gravity() -> [f32; 2] {
    [0.0, -9.81]
}
fn default_dt() -> f32 {
    1.0 / 60.0
}
fn default_substeps() -> u32 {
    4
}
fn default_steps() -> u32 {
    600
}
fn default_true() -> bool {
    true
}
fn is_true(b: &bool) -> bool {
    *b
}
fn is_zero(x: &f32) -> bool {
    *x == 0.0
}
fn is_zero2(x: &[f32; 2]) -> bool {
    x[0] == 0.0 && x[1] == 0.0
}
fn is_one(x: &f32) -> bool {
    *x == 1.0
}

/// A material: either every field, or a name from the scene's `materials`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MaterialRef {
    /// The name of a material in the scene's `materials` table.
    Named(String),
    /// A material given in place.
    Inline(MaterialSpec),
}

/// A material as written in a scene file. Friction: `friction` sets both coefficients
/// (default 0.6); `friction_static` / `friction_dynamic` override one each; when only one of
/// those two is given, the other takes the same value.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Density [kg/m²]. Default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f32>,
    /// Both friction coefficients at once. Default 0.6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f32>,
    /// Static friction μs (≥ μd).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_static: Option<f32>,
    /// Dynamic friction μd.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_dynamic: Option<f32>,
    /// Restitution e in [0, 1]. Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f32>,
    /// Approach speed below which contacts do not bounce [m/s]. Default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution_threshold: Option<f32>,
    /// Rolling resistance (dimensionless). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rolling_resistance: Option<f32>,
    /// Conveyor surface speed [m/s], clockwise around the shape. Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangent_speed: Option<f32>,
    /// Friction combine rule. Default: defer (geometric mean when both defer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_combine: Option<RuleName>,
    /// Restitution combine rule. Default: defer (max when both defer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution_combine: Option<RuleName>,
}

/// A combine rule's name in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RuleName {
    /// (a + b) / 2
    Average,
    /// √(a·b)
    GeometricMean,
    /// min(a, b)
    Min,
    /// max(a, b)
    Max,
    /// a·b
    Multiply,
}

impl From<RuleName> for CombineRule {
    fn from(r: RuleName) -> CombineRule {
        match r {
            RuleName::Average => CombineRule::Average,
            RuleName::GeometricMean => CombineRule::GeometricMean,
            RuleName::Min => CombineRule::Min,
            RuleName::Max => CombineRule::Max,
            RuleName::Multiply => CombineRule::Multiply,
        }
    }
}

impl From<CombineRule> for RuleName {
    fn from(r: CombineRule) -> RuleName {
        match r {
            CombineRule::Average => RuleName::Average,
            CombineRule::GeometricMean => RuleName::GeometricMean,
            CombineRule::Min => RuleName::Min,
            CombineRule::Max => RuleName::Max,
            CombineRule::Multiply => RuleName::Multiply,
        }
    }
}

impl MaterialSpec {
    /// The engine material this spec describes (not yet validated).
    pub fn to_material(&self) -> Material {
        let base = Material::default();
        let both = self.friction.unwrap_or(base.friction_static);
        let (mu_s, mu_d) = match (self.friction_static, self.friction_dynamic) {
            (Some(s), Some(d)) => (s, d),
            (Some(s), None) => (s, s.min(self.friction.unwrap_or(s))),
            (None, Some(d)) => (d.max(self.friction.unwrap_or(d)), d),
            (None, None) => (both, both),
        };
        Material {
            density: self.density.unwrap_or(base.density),
            friction_static: mu_s,
            friction_dynamic: mu_d,
            restitution: self.restitution.unwrap_or(base.restitution),
            restitution_threshold: self.restitution_threshold.unwrap_or(base.restitution_threshold),
            rolling_resistance: self.rolling_resistance.unwrap_or(base.rolling_resistance),
            tangent_speed: self.tangent_speed.unwrap_or(base.tangent_speed),
            friction_combine: self.friction_combine.map(Into::into),
            restitution_combine: self.restitution_combine.map(Into::into),
        }
    }

    /// A spec that writes every field of an engine material.
    pub fn from_material(m: &Material) -> MaterialSpec {
        MaterialSpec {
            density: Some(m.density),
            friction: None,
            friction_static: Some(m.friction_static),
            friction_dynamic: Some(m.friction_dynamic),
            restitution: Some(m.restitution),
            restitution_threshold: Some(m.restitution_threshold),
            rolling_resistance: Some(m.rolling_resistance),
            tangent_speed: Some(m.tangent_speed),
            friction_combine: m.friction_combine.map(Into::into),
            restitution_combine: m.restitution_combine.map(Into::into),
        }
    }
}

/// Body type in a scene file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyKind {
    /// Never moves.
    #[default]
    Static,
    /// Moves with its given velocity.
    Kinematic,
    /// Moves under forces and contacts.
    Dynamic,
}

/// A body as written in a scene file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Name used in outputs (default: the body's index).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// "static" (default), "kinematic" or "dynamic".
    #[serde(rename = "type", default)]
    pub kind: BodyKind,
    /// Body origin [m]. Default [0, 0].
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub position: [f32; 2],
    /// Rotation [rad]. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angle: f32,
    /// Velocity of the centre of mass [m/s]. Default [0, 0].
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub linear_velocity: [f32; 2],
    /// Angular velocity [rad/s]. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angular_velocity: f32,
    /// Constant force at the centre of mass [N]. Default [0, 0].
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub force: [f32; 2],
    /// Constant torque [N·m]. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub torque: f32,
    /// Gravity multiplier. Default 1.
    #[serde(default = "default_one", skip_serializing_if = "is_one")]
    pub gravity_scale: f32,
    /// Linear damping [1/s]. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub linear_damping: f32,
    /// Angular damping [1/s]. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angular_damping: f32,
    /// Prevents rotation. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub fixed_rotation: bool,
    /// A bullet: its boxes are swept along its motion even while it touches something, so
    /// it does not pass thin moving bodies (Box2D's `isBullet`). Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub bullet: bool,
    /// Whether the body starts awake. Default true.
    #[serde(default = "default_true", skip_serializing_if = "is_true")]
    pub awake: bool,
    /// Speed [m/s] (|v| + |ω|·extent) below which the body may fall asleep. Default: the
    /// engine's, 0.05 m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sleep_threshold: Option<f32>,
    /// The body's shapes.
    #[serde(default)]
    pub shapes: Vec<ShapeSpec>,
}

fn default_one() -> f32 {
    1.0
}

/// A shape as written in a scene file. `type` selects which fields apply:
/// circle {radius, center}; box {half_extents, center, angle}; polygon {vertices, radius};
/// capsule {center1, center2, radius}; segment {point1, point2}; chain {points, loop}.
/// Coordinates in the body frame [m].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeSpec {
    /// "circle", "box", "polygon", "capsule", "segment" or "chain".
    #[serde(rename = "type")]
    pub kind: String,
    /// Circle/capsule radius, or polygon rounding radius [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f32>,
    /// Circle or box centre [m]. Default [0, 0].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<[f32; 2]>,
    /// Box half extents [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_extents: Option<[f32; 2]>,
    /// Box rotation in the body frame [rad]. Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f32>,
    /// Polygon points (hulled) [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertices: Option<Vec<[f32; 2]>>,
    /// Capsule end [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center1: Option<[f32; 2]>,
    /// Capsule end [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center2: Option<[f32; 2]>,
    /// Segment end [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point1: Option<[f32; 2]>,
    /// Segment end [m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point2: Option<[f32; 2]>,
    /// Chain points [m], in order; each piece collides on its right side (wind a loop
    /// clockwise to keep shapes inside it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f32; 2]>>,
    /// Whether a chain closes into a loop (last point joined to the first). Default false.
    #[serde(default, rename = "loop", skip_serializing_if = "Option::is_none")]
    pub closed: Option<bool>,
    /// Material: a name from `materials` or an inline object. Default: the default material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialRef>,
    /// Collision filter (any shape type). Default: category 1, every mask bit, group 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<FilterSpec>,
}

/// A shape's collision filter as written in a scene file (Box2D's scheme): two shapes
/// collide when each one's category meets the other's mask, unless they share a non-zero
/// group (positive: always collide, negative: never).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterSpec {
    /// Category bits. Default 1.
    #[serde(default = "default_category")]
    pub category: u64,
    /// Mask bits: the categories this shape collides with. Default every bit.
    #[serde(default = "default_mask")]
    pub mask: u64,
    /// Group index. Default 0.
    #[serde(default)]
    pub group: i32,
}

fn default_category() -> u64 {
    1
}
fn default_mask() -> u64 {
    u64::MAX
}

impl From<FilterSpec> for Filter {
    fn from(f: FilterSpec) -> Filter {
        Filter {
            category: f.category,
            mask: f.mask,
            group: f.group,
        }
    }
}

/// A body named in a joint: its index in `bodies`, or its `name`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum BodyRef {
    /// Index in the scene's `bodies`.
    Index(usize),
    /// A body's `name` (must name exactly one body).
    Name(String),
}

/// Joint type in a scene file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKind {
    /// A hinge: the bodies share the anchor point and turn about it.
    #[default]
    Revolute,
}

/// A joint's motor as written in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorSpec {
    /// Target relative angular speed ω_B − ω_A [rad/s].
    pub speed: f32,
    /// Largest motor torque [N·m], ≥ 0 (with speed 0: joint friction).
    pub max_torque: f32,
}

/// A joint's angular spring as written in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// Frequency [Hz], > 0.
    pub hertz: f32,
    /// Damping ratio [-], ≥ 0. Default 0.
    #[serde(default)]
    pub damping_ratio: f32,
}

/// A joint as written in a scene file: a revolute joint about `anchor`, a world point at
/// the bodies' initial poses (its angle is 0 in those poses).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    /// "revolute" (the one joint type).
    #[serde(rename = "type", default)]
    pub kind: JointKind,
    /// The first body.
    pub body_a: BodyRef,
    /// The second body.
    pub body_b: BodyRef,
    /// The pivot in world coordinates at the initial poses [m].
    pub anchor: [f32; 2],
    /// Angle limits [lower, upper] [rad]. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit: Option<[f32; 2]>,
    /// Motor. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor: Option<MotorSpec>,
    /// Angular spring towards angle 0. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring: Option<SpringSpec>,
    /// B's rotation relative to A [rad] at which the joint angle is 0 (the angle the limit,
    /// the spring and the reported angle are measured from). Default: the bodies' relative
    /// rotation in the file, so the joint angle starts at 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_angle: Option<f32>,
    /// Whether the two bodies' shapes still collide. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub collide_connected: bool,
    /// Soft position correction [Hz]. Default 60.
    #[serde(
        default = "default_constraint_hertz",
        skip_serializing_if = "is_default_constraint_hertz"
    )]
    pub constraint_hertz: f32,
    /// Damping ratio of the position correction [-]. Default 2.
    #[serde(
        default = "default_constraint_damping",
        skip_serializing_if = "is_default_constraint_damping"
    )]
    pub constraint_damping_ratio: f32,
}

fn default_constraint_hertz() -> f32 {
    tribo::DEFAULT_CONSTRAINT_HERTZ
}
fn is_default_constraint_hertz(x: &f32) -> bool {
    *x == tribo::DEFAULT_CONSTRAINT_HERTZ
}
fn default_constraint_damping() -> f32 {
    tribo::DEFAULT_CONSTRAINT_DAMPING_RATIO
}
fn is_default_constraint_damping(x: &f32) -> bool {
    *x == tribo::DEFAULT_CONSTRAINT_DAMPING_RATIO
}

impl JointSpec {
    /// A plain revolute joint between two bodies (by index) about a world point [m].
    pub fn revolute(body_a: usize, body_b: usize, anchor: [f32; 2]) -> JointSpec {
        JointSpec {
            kind: JointKind::Revolute,
            body_a: BodyRef::Index(body_a),
            body_b: BodyRef::Index(body_b),
            anchor,
            limit: None,
            motor: None,
            spring: None,
            reference_angle: None,
            collide_connected: false,
            constraint_hertz: tribo::DEFAULT_CONSTRAINT_HERTZ,
            constraint_damping_ratio: tribo::DEFAULT_CONSTRAINT_DAMPING_RATIO,
        }
    }
}

/// What is wrong with a scene file, and where.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// JSON path of the offending value, e.g. `bodies[3].shapes[0].radius` (empty for the
    /// whole document).
    pub path: String,
    /// 1-based line and column in the file, when known.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let place = if self.path.is_empty() {
            "(document)".to_string()
        } else {
            self.path.clone()
        };
        if self.line > 0 {
            write!(
                f,
                "{place} (line {}, column {}): {}",
                self.line, self.column, self.message
            )
        } else {
            write!(f, "{place}: {}", self.message)
        }
    }
}

impl std::error::Error for SceneError {}

/// Parses a scene file's text. Errors carry the JSON path and line:column.
pub fn parse(text: &str) -> Result<SceneFile, SceneError> {
    // Syntax first: serde_json reports line and column of malformed or truncated JSON.
    if let Err(e) = serde_json::from_str::<serde::de::IgnoredAny>(text) {
        return Err(SceneError {
            path: String::new(),
            line: e.line(),
            column: e.column(),
            message: format!("invalid JSON: {}", strip_position(&e.to_string())),
        });
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    let scene: SceneFile = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = clean_path(&e.path().to_string());
        let inner = e.into_inner();
        let (line, column) = if inner.line() > 0 {
            (inner.line(), inner.column())
        } else {
            locate_path(text, &path).unwrap_or((0, 0))
        };
        SceneError {
            path,
            line,
            column,
            message: strip_position(&inner.to_string()),
        }
    })?;
    scene.validate().map_err(|(path, message)| {
        let (line, column) = locate_nearest(text, &path).unwrap_or((0, 0));
        SceneError {
            path,
            line,
            column,
            message,
        }
    })?;
    Ok(scene)
}

/// The line:column of `path` in `text`, or of the closest enclosing value that is there (a
/// missing field's error names the field; its object is where to look).
fn locate_nearest(text: &str, path: &str) -> Option<(usize, usize)> {
    let mut p = path;
    loop {
        if let Some(at) = locate_path(text, p) {
            return Some(at);
        }
        let cut = p.rfind(['.', '['])?;
        p = &p[..cut];
    }
}

/// serde_path_to_error writes `.` for the root and `?` for unknown positions.
fn clean_path(p: &str) -> String {
    if p == "." || p == "?" {
        String::new()
    } else {
        p.to_string()
    }
}

/// Removes serde_json's " at line L column C" suffix (we print the position ourselves).
fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_string(),
        None => msg.to_string(),
    }
}

type Invalid = (String, String);

fn finite(path: &str, v: f32) -> Result<(), Invalid> {
    if v.is_finite() {
        Ok(())
    } else {
        Err((path.to_string(), format!("must be a finite number (got {v})")))
    }
}

fn non_negative(path: &str, v: f32) -> Result<(), Invalid> {
    finite(path, v)?;
    if v < 0.0 {
        return Err((path.to_string(), format!("must not be negative (got {v})")));
    }
    Ok(())
}

fn finite2(path: &str, v: [f32; 2]) -> Result<(), Invalid> {
    if v[0].is_finite() && v[1].is_finite() {
        Ok(())
    } else {
        Err((
            path.to_string(),
            format!("must be finite numbers (got [{}, {}])", v[0], v[1]),
        ))
    }
}

impl SceneFile {
    /// Checks ranges and references; returns the path and message of the first problem.
    pub fn validate(&self) -> Result<(), Invalid> {
        self.checked_geometries().map(|_| ())
    }

    /// [`SceneFile::validate`], keeping the engine shape of every shape (by body, then
    /// shape) so that building does not make each one (polygon hulls included) twice.
    fn checked_geometries(&self) -> Result<Vec<Vec<Vec<Shape>>>, Invalid> {
        finite2("gravity", self.gravity)?;
        finite("dt", self.dt)?;
        if self.dt <= 0.0 || self.dt > 1.0 {
            return Err(("dt".into(), format!("must be in (0, 1] seconds (got {})", self.dt)));
        }
        if self.substeps == 0 || self.substeps > 64 {
            return Err(("substeps".into(), format!("must be in 1..=64 (got {})", self.substeps)));
        }
        for (name, m) in &self.materials {
            validate_material(&format!("materials.{name}"), m)?;
        }
        let mut geometries = Vec::with_capacity(self.bodies.len());
        for (i, b) in self.bodies.iter().enumerate() {
            let p = format!("bodies[{i}]");
            finite2(&format!("{p}.position"), b.position)?;
            finite(&format!("{p}.angle"), b.angle)?;
            finite2(&format!("{p}.linear_velocity"), b.linear_velocity)?;
            finite(&format!("{p}.angular_velocity"), b.angular_velocity)?;
            finite2(&format!("{p}.force"), b.force)?;
            finite(&format!("{p}.torque"), b.torque)?;
            finite(&format!("{p}.gravity_scale"), b.gravity_scale)?;
            if let Some(t) = b.sleep_threshold {
                non_negative(&format!("{p}.sleep_threshold"), t)?;
            }
            for (field, v) in [
                ("linear_damping", b.linear_damping),
                ("angular_damping", b.angular_damping),
            ] {
                finite(&format!("{p}.{field}"), v)?;
                if v < 0.0 {
                    return Err((format!("{p}.{field}"), format!("must not be negative (got {v})")));
                }
            }
            let mut shapes = Vec::with_capacity(b.shapes.len());
            for (j, s) in b.shapes.iter().enumerate() {
                let sp = format!("{p}.shapes[{j}]");
                shapes.push(self.shape_geometry(&sp, s)?);
                match &s.material {
                    Some(MaterialRef::Named(n)) if !self.materials.contains_key(n) => {
                        let known: Vec<&str> = self.materials.keys().map(String::as_str).collect();
                        return Err((
                            format!("{sp}.material"),
                            format!("unknown material \"{n}\" (defined: {})", list_or_none(&known)),
                        ));
                    }
                    Some(MaterialRef::Inline(m)) => validate_material(&format!("{sp}.material"), m)?,
                    _ => {}
                }
            }
            geometries.push(shapes);
        }
        for (i, j) in self.joints.iter().enumerate() {
            self.validate_joint(&format!("joints[{i}]"), j)?;
        }
        Ok(geometries)
    }

    /// The index of the body a joint names, with errors at `path`.
    pub fn resolve_body(&self, path: &str, r: &BodyRef) -> Result<usize, Invalid> {
        match r {
            BodyRef::Index(i) if *i < self.bodies.len() => Ok(*i),
            BodyRef::Index(i) => Err((
                path.to_string(),
                format!("no body {i} (the scene has {} bodies)", self.bodies.len()),
            )),
            BodyRef::Name(n) => {
                let mut found = self
                    .bodies
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| b.name.as_deref() == Some(n));
                match (found.next(), found.next()) {
                    (Some((i, _)), None) => Ok(i),
                    (None, _) => Err((path.to_string(), format!("no body is named \"{n}\""))),
                    (Some(_), Some(_)) => Err((
                        path.to_string(),
                        format!("several bodies are named \"{n}\" (use the body's index)"),
                    )),
                }
            }
        }
    }

    fn validate_joint(&self, p: &str, j: &JointSpec) -> Result<(), Invalid> {
        let a = self.resolve_body(&format!("{p}.body_a"), &j.body_a)?;
        let b = self.resolve_body(&format!("{p}.body_b"), &j.body_b)?;
        if a == b {
            return Err((
                format!("{p}.body_b"),
                format!("must differ from body_a (both are body {a})"),
            ));
        }
        finite2(&format!("{p}.anchor"), j.anchor)?;
        if let Some([lower, upper]) = j.limit {
            finite2(&format!("{p}.limit"), [lower, upper])?;
            if lower > upper {
                return Err((
                    format!("{p}.limit"),
                    format!("lower must be ≤ upper (got [{lower}, {upper}])"),
                ));
            }
        }
        if let Some(r) = j.reference_angle {
            finite(&format!("{p}.reference_angle"), r)?;
        }
        if let Some(m) = j.motor {
            finite(&format!("{p}.motor.speed"), m.speed)?;
            non_negative(&format!("{p}.motor.max_torque"), m.max_torque)?;
        }
        if let Some(sp) = j.spring {
            finite(&format!("{p}.spring.hertz"), sp.hertz)?;
            if sp.hertz <= 0.0 {
                return Err((
                    format!("{p}.spring.hertz"),
                    format!("must be positive (got {})", sp.hertz),
                ));
            }
            non_negative(&format!("{p}.spring.damping_ratio"), sp.damping_ratio)?;
        }
        non_negative(&format!("{p}.constraint_hertz"), j.constraint_hertz)?;
        non_negative(&format!("{p}.constraint_damping_ratio"), j.constraint_damping_ratio)?;
        Ok(())
    }

    /// The engine shapes of a shape spec (one, or a chain's pieces), with errors at `path`.
    pub fn shape_geometry(&self, path: &str, s: &ShapeSpec) -> Result<Vec<Shape>, Invalid> {
        let allowed: &[&str] = match s.kind.as_str() {
            "circle" => &["radius", "center"],
            "box" => &["half_extents", "center", "angle"],
            "polygon" => &["vertices", "radius"],
            "capsule" => &["center1", "center2", "radius"],
            "segment" => &["point1", "point2"],
            "chain" => &["points", "loop"],
            other => {
                return Err((
                    format!("{path}.type"),
                    format!(
                        "unknown shape type \"{other}\" (expected circle, box, polygon, capsule, segment or chain)"
                    ),
                ))
            }
        };
        let present = [
            ("radius", s.radius.is_some()),
            ("center", s.center.is_some()),
            ("half_extents", s.half_extents.is_some()),
            ("angle", s.angle.is_some()),
            ("vertices", s.vertices.is_some()),
            ("center1", s.center1.is_some()),
            ("center2", s.center2.is_some()),
            ("point1", s.point1.is_some()),
            ("point2", s.point2.is_some()),
            ("points", s.points.is_some()),
            ("loop", s.closed.is_some()),
        ];
        for (field, is) in present {
            if is && !allowed.contains(&field) {
                return Err((
                    format!("{path}.{field}"),
                    format!(
                        "field \"{field}\" does not apply to a {} (its fields: {})",
                        s.kind,
                        allowed.join(", ")
                    ),
                ));
            }
        }
        let need = |field: &str| (format!("{path}.{field}"), format!("a {} needs \"{field}\"", s.kind));
        let geo = |field: &str, e: tribo::GeometryError| (format!("{path}.{field}"), e.to_string());
        let v = |a: [f32; 2]| Vec2::new(a[0], a[1]);
        let shape = match s.kind.as_str() {
            "circle" => {
                let r = s.radius.ok_or_else(|| need("radius"))?;
                let c = s.center.unwrap_or([0.0, 0.0]);
                finite2(&format!("{path}.center"), c)?;
                Shape::Circle(Circle::new(v(c), r).map_err(|e| geo("radius", e))?)
            }
            "box" => {
                let h = s.half_extents.ok_or_else(|| need("half_extents"))?;
                let c = s.center.unwrap_or([0.0, 0.0]);
                let a = s.angle.unwrap_or(0.0);
                finite2(&format!("{path}.center"), c)?;
                finite(&format!("{path}.angle"), a)?;
                Shape::Polygon(Polygon::new_offset_box(h[0], h[1], v(c), a).map_err(|e| geo("half_extents", e))?)
            }
            "polygon" => {
                let pts = s.vertices.as_ref().ok_or_else(|| need("vertices"))?;
                let pts: Vec<Vec2> = pts.iter().map(|&p| v(p)).collect();
                let r = s.radius.unwrap_or(0.0);
                Shape::Polygon(Polygon::from_points(&pts, r).map_err(|e| geo("vertices", e))?)
            }
            "capsule" => {
                let c1 = s.center1.ok_or_else(|| need("center1"))?;
                let c2 = s.center2.ok_or_else(|| need("center2"))?;
                let r = s.radius.ok_or_else(|| need("radius"))?;
                Shape::Capsule(Capsule::new(v(c1), v(c2), r).map_err(|e| geo("center2", e))?)
            }
            "chain" => {
                let pts = s.points.as_ref().ok_or_else(|| need("points"))?;
                for (k, &p) in pts.iter().enumerate() {
                    finite2(&format!("{path}.points[{k}]"), p)?;
                }
                let closed = s.closed.unwrap_or(false);
                let pts: Vec<Vec2> = pts.iter().map(|&p| v(p)).collect();
                // Name the point that ends a too short piece.
                if let Some(end) = ChainSegment::short_piece(&pts, closed) {
                    let start = (end + pts.len() - 1) % pts.len();
                    return Err((
                        format!("{path}.points[{end}]"),
                        format!(
                            "chain point {end} lies within {} m of point {start}: pieces must be at least that long",
                            tribo::geometry::LINEAR_SLOP
                        ),
                    ));
                }
                let pieces = ChainSegment::chain(&pts, closed).map_err(|e| geo("points", e))?;
                return Ok(pieces.into_iter().map(Shape::ChainSegment).collect());
            }
            _ => {
                let p1 = s.point1.ok_or_else(|| need("point1"))?;
                let p2 = s.point2.ok_or_else(|| need("point2"))?;
                Shape::Segment(Segment::new(v(p1), v(p2)).map_err(|e| geo("point2", e))?)
            }
        };
        Ok(vec![shape])
    }

    /// The engine material of a shape spec (validated by [`SceneFile::validate`]).
    pub fn shape_material(&self, s: &ShapeSpec) -> Material {
        match &s.material {
            None => Material::default(),
            Some(MaterialRef::Inline(m)) => m.to_material(),
            Some(MaterialRef::Named(n)) => self.materials.get(n).map(|m| m.to_material()).unwrap_or_default(),
        }
    }

    /// The name of a body as outputs show it: its name, or its index.
    pub fn body_name(&self, index: usize) -> String {
        self.bodies
            .get(index)
            .and_then(|b| b.name.clone())
            .unwrap_or_else(|| index.to_string())
    }

    /// Builds the world. The scene must have passed [`SceneFile::validate`] (parse does it).
    pub fn build(&self) -> Result<BuiltScene, SceneError> {
        // `add_to` validates the scene before adding anything.
        let mut world = World::new(WorldDef {
            gravity: Vec2::new(self.gravity[0], self.gravity[1]),
            substeps: self.substeps,
            enable_sleep: self.enable_sleep,
            ..WorldDef::default()
        })
        .map_err(|e| SceneError {
            path: String::new(),
            line: 0,
            column: 0,
            message: e.to_string(),
        })?;
        let bodies = self.add_to(&mut world)?;
        Ok(BuiltScene {
            world,
            bodies,
            dt: self.dt,
            steps: self.steps,
        })
    }

    /// Adds the scene's bodies and joints to an existing world (its world settings —
    /// gravity, dt, substeps, sleep — are not used) and returns the new bodies in scene
    /// order. Validates first: on an error nothing is added. A world-level error part way
    /// (the world refusing a body) leaves what was added so far.
    pub fn add_to(&self, world: &mut World) -> Result<Vec<BodyId>, SceneError> {
        let geometries = self.checked_geometries().map_err(|(path, message)| SceneError {
            path,
            line: 0,
            column: 0,
            message,
        })?;
        let to_err = |path: String| {
            move |e: tribo::Error| SceneError {
                path: path.clone(),
                line: 0,
                column: 0,
                message: e.to_string(),
            }
        };
        let mut bodies = Vec::with_capacity(self.bodies.len());
        for ((i, b), shapes) in self.bodies.iter().enumerate().zip(&geometries) {
            let p = format!("bodies[{i}]");
            let def = BodyDef {
                body_type: match b.kind {
                    BodyKind::Static => BodyType::Static,
                    BodyKind::Kinematic => BodyType::Kinematic,
                    BodyKind::Dynamic => BodyType::Dynamic,
                },
                position: Vec2::new(b.position[0], b.position[1]),
                angle: b.angle,
                linear_velocity: Vec2::new(b.linear_velocity[0], b.linear_velocity[1]),
                angular_velocity: b.angular_velocity,
                linear_damping: b.linear_damping,
                angular_damping: b.angular_damping,
                gravity_scale: b.gravity_scale,
                fixed_rotation: b.fixed_rotation,
                bullet: b.bullet,
                constant_force: Vec2::new(b.force[0], b.force[1]),
                constant_torque: b.torque,
                awake: b.awake,
                sleep_threshold: b.sleep_threshold.unwrap_or(BodyDef::default().sleep_threshold),
                user_data: i as u64,
                ..BodyDef::default()
            };
            let id = world.create_body(&def).map_err(to_err(p.clone()))?;
            for (j, (s, pieces)) in b.shapes.iter().zip(shapes).enumerate() {
                let sp = format!("{p}.shapes[{j}]");
                let def = ShapeDef {
                    material: self.shape_material(s),
                    filter: s.filter.map(Into::into).unwrap_or_default(),
                    ..ShapeDef::default()
                };
                for geometry in pieces {
                    world.create_shape(id, &def, geometry).map_err(to_err(sp.clone()))?;
                }
            }
            // The velocity in the file is that of the centre of mass: set it after the
            // shapes moved the centre.
            if b.kind != BodyKind::Static {
                world
                    .set_body_linear_velocity(id, def.linear_velocity)
                    .map_err(to_err(format!("{p}.linear_velocity")))?;
                // Setting a velocity wakes a body: put one created asleep back to sleep
                // (alone, as Box2D creates each sleeping body in its own set).
                if !b.awake {
                    world.set_body_awake(id, false).map_err(to_err(format!("{p}.awake")))?;
                }
            }
            bodies.push(id);
        }
        for (i, j) in self.joints.iter().enumerate() {
            let p = format!("joints[{i}]");
            let invalid = |(path, message): Invalid| SceneError {
                path,
                line: 0,
                column: 0,
                message,
            };
            let a = bodies[self.resolve_body(&p, &j.body_a).map_err(invalid)?];
            let b = bodies[self.resolve_body(&p, &j.body_b).map_err(invalid)?];
            let mut def = RevoluteJointDef::at(world, a, b, Vec2::new(j.anchor[0], j.anchor[1]))
                .map_err(to_err(format!("{p}.anchor")))?;
            if let Some(r) = j.reference_angle {
                def.reference_angle = r;
            }
            if let Some([lower, upper]) = j.limit {
                def = def.limit(lower, upper);
            }
            if let Some(m) = j.motor {
                def = def.motor(m.speed, m.max_torque);
            }
            if let Some(sp) = j.spring {
                def = def.spring(sp.hertz, sp.damping_ratio);
            }
            def.collide_connected = j.collide_connected;
            def.constraint_hertz = j.constraint_hertz;
            def.constraint_damping_ratio = j.constraint_damping_ratio;
            def.user_data = i as u64;
            world.create_revolute_joint(&def).map_err(to_err(p))?;
        }
        Ok(bodies)
    }

    /// The scene as pretty JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

fn list_or_none(names: &[&str]) -> String {
    if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    }
}

fn validate_material(path: &str, m: &MaterialSpec) -> Result<(), Invalid> {
    let fields = [
        ("density", m.density),
        ("friction", m.friction),
        ("friction_static", m.friction_static),
        ("friction_dynamic", m.friction_dynamic),
        ("restitution", m.restitution),
        ("restitution_threshold", m.restitution_threshold),
        ("rolling_resistance", m.rolling_resistance),
        ("tangent_speed", m.tangent_speed),
    ];
    for (field, v) in fields {
        if let Some(v) = v {
            finite(&format!("{path}.{field}"), v)?;
            if field != "tangent_speed" && v < 0.0 {
                return Err((format!("{path}.{field}"), format!("must not be negative (got {v})")));
            }
        }
    }
    if let Some(e) = m.restitution {
        if e > 1.0 {
            return Err((format!("{path}.restitution"), format!("must be in [0, 1] (got {e})")));
        }
    }
    let mat = m.to_material();
    if mat.friction_static < mat.friction_dynamic {
        let field = if m.friction_static.is_some() {
            "friction_static"
        } else {
            "friction_dynamic"
        };
        return Err((
            format!("{path}.{field}"),
            format!(
                "static friction ({}) must be at least the dynamic friction ({})",
                mat.friction_static, mat.friction_dynamic
            ),
        ));
    }
    mat.validate().map_err(|e| (path.to_string(), e.to_string()))
}

/// A world built from a scene, with what the outputs need.
pub struct BuiltScene {
    /// The world.
    pub world: World,
    /// Body ids in scene order (index i is `bodies[i]`).
    pub bodies: Vec<BodyId>,
    /// Step length [s].
    pub dt: f32,
    /// Steps to run.
    pub steps: u32,
}
