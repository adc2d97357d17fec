//! What a picture shows: the shapes and contact points of one instant, in world
//! coordinates [m]. Built by the CLI from a `tribo::World`, drawn by `render`.

/// One drawable shape in world coordinates [m].
#[derive(Clone, Debug, PartialEq)]
pub enum DrawKind {
    /// A circle; `angle` [rad] is the body's rotation (drawn as a radius line so spin shows).
    Circle {
        /// Centre [m].
        center: [f32; 2],
        /// Radius [m].
        radius: f32,
        /// Rotation of the body [rad].
        angle: f32,
    },
    /// A convex polygon, counter-clockwise, grown by `radius` [m] (rounded corners).
    Polygon {
        /// Vertices [m].
        points: Vec<[f32; 2]>,
        /// Rounding radius [m] (0 for sharp corners).
        radius: f32,
    },
    /// A capsule: all points within `radius` of the segment p1–p2.
    Capsule {
        /// First end [m].
        p1: [f32; 2],
        /// Second end [m].
        p2: [f32; 2],
        /// Radius [m].
        radius: f32,
    },
    /// A line segment (ground).
    Segment {
        /// First end [m].
        p1: [f32; 2],
        /// Second end [m].
        p2: [f32; 2],
        /// For a one-sided chain piece: the unit direction [world axes] of its solid side
        /// (where the ground ticks go); `None` for a two-sided segment (ticks below).
        back: Option<[f32; 2]>,
    },
}

/// A shape with its look.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawShape {
    /// Geometry.
    pub kind: DrawKind,
    /// Fill colour (sRGB), chosen per material by the caller.
    pub fill: [u8; 3],
    /// Static bodies (ground) are drawn in a muted ground style.
    pub is_static: bool,
    /// Sleeping bodies may be drawn dimmer.
    pub asleep: bool,
}

/// A contact point.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawContact {
    /// World position [m].
    pub point: [f32; 2],
    /// Unit normal.
    pub normal: [f32; 2],
    /// True if the point sticks (static friction holds), false if it slips.
    pub stick: bool,
}

/// Everything drawn at one instant.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Frame {
    /// Simulation time [s].
    pub time: f32,
    /// Shapes, drawn in order (static first is a good idea).
    pub shapes: Vec<DrawShape>,
    /// Contact points, drawn on top.
    pub contacts: Vec<DrawContact>,
    /// Joint pivots [m] (each as body B holds it), drawn as small rings on top.
    pub joints: Vec<[f32; 2]>,
}
