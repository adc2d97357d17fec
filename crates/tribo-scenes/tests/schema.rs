//! Keeps `docs/scene.schema.json` (and the example in `docs/scene-format.md`) in step with
//! the serde types of the scene format in `tribo_scenes::format`.
//!
//! - the schema is JSON, draft 2020-12, and every `$ref` resolves;
//! - the property names of scene, material, body, shapes, filter, joint, motor and spring
//!   are exactly the serde fields (found by serializing a scene with every optional field
//!   set);
//! - the enums (body type, shape type, combine rules, joint type) are exactly the serde
//!   variants;
//! - each shape type's fields and required fields in the schema are what the loader accepts
//!   and requires, and every `default` in the schema is what the loader uses;
//! - every built-in scene, and the documentation's example, only use what the schema knows.

use serde_json::{json, Map, Value};
use std::collections::{BTreeMap, BTreeSet};
use tribo::Material;
use tribo_scenes::format::{
    self, BodyKind, BodyRef, BodySpec, FilterSpec, JointKind, JointSpec, MaterialRef, MaterialSpec, MotorSpec,
    RuleName, SceneFile, ShapeSpec, SpringSpec,
};
use tribo_scenes::scenes::SCENES;

const SCHEMA: &str = include_str!("../../../docs/scene.schema.json");
const DOC: &str = include_str!("../../../docs/scene-format.md");

fn schema() -> Value {
    serde_json::from_str(SCHEMA).expect("docs/scene.schema.json is valid JSON")
}

/// Follows a local `$ref` (`#/$defs/name`), repeatedly.
fn resolve<'a>(root: &'a Value, node: &'a Value) -> &'a Value {
    let mut node = node;
    while let Some(r) = node.get("$ref").and_then(Value::as_str) {
        let pointer = r.strip_prefix('#').unwrap_or_else(|| panic!("non-local $ref {r}"));
        node = root
            .pointer(pointer)
            .unwrap_or_else(|| panic!("$ref {r} does not resolve"));
    }
    node
}

fn def<'a>(root: &'a Value, name: &str) -> &'a Value {
    root.pointer(&format!("/$defs/{name}"))
        .unwrap_or_else(|| panic!("schema has no $defs/{name}"))
}

fn properties(node: &Value) -> &Map<String, Value> {
    node.get("properties")
        .and_then(Value::as_object)
        .expect("node has \"properties\"")
}

fn prop_names(node: &Value) -> BTreeSet<String> {
    properties(node).keys().cloned().collect()
}

fn keys(v: &Value) -> BTreeSet<String> {
    v.as_object().expect("an object").keys().cloned().collect()
}

fn required(node: &Value) -> BTreeSet<String> {
    node.get("required")
        .and_then(Value::as_array)
        .map(|a| a.iter().map(|s| s.as_str().expect("string").to_string()).collect())
        .unwrap_or_default()
}

/// The shape variants of the schema: type name → resolved variant schema.
fn shape_variants(root: &Value) -> BTreeMap<String, &Value> {
    let one_of = def(root, "shape")["oneOf"].as_array().expect("shape has oneOf");
    let mut out = BTreeMap::new();
    for branch in one_of {
        let variant = resolve(root, branch);
        let name = properties(variant)["type"]["const"]
            .as_str()
            .expect("each shape variant fixes \"type\" with const")
            .to_string();
        assert!(
            out.insert(name.clone(), variant).is_none(),
            "shape type {name} listed twice"
        );
    }
    out
}

fn enum_strings(node: &Value) -> BTreeSet<String> {
    node["enum"]
        .as_array()
        .expect("node has \"enum\"")
        .iter()
        .filter_map(|v| v.as_str().map(str::to_string))
        .collect()
}

/// Whether a field holds numbers (a number, or an array of numbers or of vectors).
fn is_numeric(root: &Value, node: &Value) -> bool {
    let node = resolve(root, node);
    match node["type"].as_str() {
        Some("number" | "integer") => true,
        Some("array") => is_numeric(root, &node["items"]),
        _ => false,
    }
}

fn to_value<T: serde::Serialize>(t: &T) -> Value {
    serde_json::to_value(t).expect("serializes")
}

// ---------------------------------------------------------------------------------------
// A scene with every optional field set (struct literals without `..Default::default()`,
// so a new field fails to compile here until the test, and so the schema, knows it).

fn full_material() -> MaterialSpec {
    MaterialSpec {
        density: Some(2.0),
        friction: Some(0.5),
        friction_static: Some(0.7),
        friction_dynamic: Some(0.4),
        restitution: Some(0.3),
        restitution_threshold: Some(0.5),
        rolling_resistance: Some(0.1),
        tangent_speed: Some(-1.0),
        friction_combine: Some(RuleName::Min),
        restitution_combine: Some(RuleName::Average),
    }
}

fn full_shape() -> ShapeSpec {
    // Not a valid shape (it has every type's fields); only its keys matter.
    ShapeSpec {
        kind: "circle".into(),
        radius: Some(0.5),
        center: Some([0.1, 0.2]),
        half_extents: Some([0.5, 0.25]),
        angle: Some(0.3),
        vertices: Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        center1: Some([0.0, 0.0]),
        center2: Some([1.0, 0.0]),
        point1: Some([0.0, 0.0]),
        point2: Some([1.0, 0.0]),
        points: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]),
        closed: Some(true),
        material: Some(MaterialRef::Inline(full_material())),
        filter: Some(FilterSpec {
            category: 2,
            mask: 5,
            group: -1,
        }),
    }
}

fn full_joint() -> JointSpec {
    JointSpec {
        kind: JointKind::Revolute,
        body_a: BodyRef::Index(0),
        body_b: BodyRef::Name("b".into()),
        anchor: [1.0, 2.0],
        limit: Some([-0.5, 0.5]),
        motor: Some(MotorSpec {
            speed: 1.0,
            max_torque: 10.0,
        }),
        spring: Some(SpringSpec {
            hertz: 2.0,
            damping_ratio: 0.3,
        }),
        reference_angle: Some(0.25),
        collide_connected: true,
        constraint_hertz: 30.0,
        constraint_damping_ratio: 1.0,
    }
}

fn full_body() -> BodySpec {
    BodySpec {
        name: Some("b".into()),
        kind: BodyKind::Dynamic,
        position: [1.0, 2.0],
        angle: 0.5,
        linear_velocity: [1.0, 0.0],
        angular_velocity: 1.0,
        force: [0.0, 1.0],
        torque: 2.0,
        gravity_scale: 0.5,
        linear_damping: 0.1,
        angular_damping: 0.2,
        fixed_rotation: true,
        bullet: true,
        awake: false,
        sleep_threshold: Some(0.1),
        shapes: vec![full_shape()],
    }
}

fn full_scene() -> SceneFile {
    SceneFile {
        description: Some("every field".into()),
        gravity: [0.0, -10.0],
        dt: 0.01,
        substeps: 8,
        steps: 10,
        enable_sleep: false,
        materials: BTreeMap::from([("m".to_string(), full_material())]),
        bodies: vec![full_body()],
        joints: vec![full_joint()],
    }
}

fn all_body_kinds() -> Vec<BodyKind> {
    let all = vec![BodyKind::Static, BodyKind::Kinematic, BodyKind::Dynamic];
    for k in &all {
        // Exhaustive: a new variant fails to compile here.
        match k {
            BodyKind::Static | BodyKind::Kinematic | BodyKind::Dynamic => {}
        }
    }
    all
}

fn all_rules() -> Vec<RuleName> {
    let all = vec![
        RuleName::Average,
        RuleName::GeometricMean,
        RuleName::Min,
        RuleName::Max,
        RuleName::Multiply,
    ];
    for r in &all {
        match r {
            RuleName::Average | RuleName::GeometricMean | RuleName::Min | RuleName::Max | RuleName::Multiply => {}
        }
    }
    all
}

/// A valid value for each shape field, for building test shapes.
fn sample(field: &str) -> Value {
    match field {
        "radius" => json!(0.5),
        "center" => json!([0.1, 0.2]),
        "half_extents" => json!([0.5, 0.25]),
        "angle" => json!(0.3),
        "vertices" => json!([[0, 0], [1, 0], [0, 1]]),
        "center1" | "point1" => json!([0, 0]),
        "center2" | "point2" => json!([1, 0]),
        "points" => json!([[0, 0], [1, 0], [1, 1]]),
        "loop" => json!(true),
        "material" => json!({ "friction": 0.5 }),
        "filter" => json!({ "category": 2, "mask": 1, "group": 0 }),
        other => panic!("no sample value for shape field {other}"),
    }
}

fn scene_with_shape(shape: &Value) -> String {
    json!({ "bodies": [ { "type": "dynamic", "shapes": [shape] } ] }).to_string()
}

// ---------------------------------------------------------------------------------------
// (a) the schema parses.

#[test]
fn schema_is_json_draft_2020_12_and_refs_resolve() {
    let root = schema();
    assert_eq!(root["$schema"], "https://json-schema.org/draft/2020-12/schema");
    assert_eq!(root["type"], "object");
    fn walk(root: &Value, v: &Value) {
        match v {
            Value::Object(m) => {
                if m.contains_key("$ref") {
                    resolve(root, v);
                }
                m.values().for_each(|c| walk(root, c));
            }
            Value::Array(a) => a.iter().for_each(|c| walk(root, c)),
            _ => {}
        }
    }
    walk(&root, &root);
}

#[test]
fn every_object_forbids_unknown_fields() {
    let root = schema();
    fn walk(v: &Value, path: &str) {
        if let Value::Object(m) = v {
            if m.contains_key("properties") {
                assert!(
                    m.get("additionalProperties") == Some(&Value::Bool(false)),
                    "{path}: an object with properties must have additionalProperties false"
                );
            }
            for (k, c) in m {
                walk(c, &format!("{path}/{k}"));
            }
        } else if let Value::Array(a) = v {
            for (i, c) in a.iter().enumerate() {
                walk(c, &format!("{path}/{i}"));
            }
        }
    }
    // `$defs/shape` only selects the variant (its `properties` lists `type`); the variants
    // themselves forbid other fields.
    let mut root = root;
    root["$defs"]["shape"]
        .as_object_mut()
        .expect("shape")
        .remove("properties");
    walk(&root, "#");
}

#[test]
fn every_field_has_a_description_with_unit_and_a_default() {
    let root = schema();
    // Fields that are optional but have no fixed value to write as "default".
    let no_default = [
        "description",
        "name",
        "material",
        "filter",
        "limit",
        "motor",
        "spring",
        "reference_angle",
        "sleep_threshold",
    ];
    let mut objects: Vec<(String, &Value)> = vec![
        ("scene".into(), &root),
        ("material".into(), def(&root, "material")),
        ("body".into(), def(&root, "body")),
        ("filter".into(), def(&root, "filter")),
        ("joint".into(), def(&root, "joint")),
        ("motor".into(), def(&root, "motor")),
        ("spring".into(), def(&root, "spring")),
    ];
    for (name, v) in shape_variants(&root) {
        objects.push((name, v));
    }
    for (object, node) in objects {
        let req = required(node);
        for (field, prop) in properties(node) {
            let description = prop["description"]
                .as_str()
                .unwrap_or_else(|| panic!("{object}.{field}: no description"));
            let has_default = prop.get("default").is_some();
            if req.contains(field) || no_default.contains(&field.as_str()) {
                assert!(
                    !has_default,
                    "{object}.{field}: required or default-less, but has a default"
                );
            } else {
                assert!(has_default, "{object}.{field}: optional but no default");
            }
            if is_numeric(&root, prop) {
                assert!(
                    description.contains('[') && description.contains(']'),
                    "{object}.{field}: numeric, but no [unit] in the description: {description}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// (b) the schema's property names are exactly the serde fields.

#[test]
fn schema_properties_are_the_serde_fields() {
    let root = schema();
    let full = to_value(&full_scene());

    assert_eq!(keys(&full), prop_names(&root), "scene fields");

    let material = def(&root, "material");
    assert_eq!(keys(&full["materials"]["m"]), prop_names(material), "material fields");
    assert_eq!(
        keys(&full["bodies"][0]["shapes"][0]["material"]),
        prop_names(material),
        "inline material fields"
    );

    assert_eq!(keys(&full["bodies"][0]), prop_names(def(&root, "body")), "body fields");
    assert_eq!(
        keys(&full["bodies"][0]["shapes"][0]["filter"]),
        prop_names(def(&root, "filter")),
        "filter fields"
    );
    let joint = &full["joints"][0];
    assert_eq!(keys(joint), prop_names(def(&root, "joint")), "joint fields");
    assert_eq!(keys(&joint["motor"]), prop_names(def(&root, "motor")), "motor fields");
    assert_eq!(
        keys(&joint["spring"]),
        prop_names(def(&root, "spring")),
        "spring fields"
    );

    let variants = shape_variants(&root);
    let union: BTreeSet<String> = variants.values().flat_map(|v| prop_names(v)).collect();
    assert_eq!(keys(&full["bodies"][0]["shapes"][0]), union, "shape fields (all types)");
    for (name, v) in &variants {
        let names = prop_names(v);
        assert!(
            names.contains("type") && names.contains("material") && names.contains("filter"),
            "{name}: type, material and filter"
        );
    }
}

#[test]
fn schema_enums_are_the_serde_variants() {
    let root = schema();
    let kinds: BTreeSet<String> = all_body_kinds()
        .iter()
        .map(|k| to_value(k).as_str().expect("string").to_string())
        .collect();
    assert_eq!(kinds, enum_strings(&properties(def(&root, "body"))["type"]));

    let rules: BTreeSet<String> = all_rules()
        .iter()
        .map(|r| to_value(r).as_str().expect("string").to_string())
        .collect();
    let rule_node = def(&root, "combineRule");
    assert_eq!(rules, enum_strings(rule_node));
    assert!(
        rule_node["enum"].as_array().expect("enum").contains(&Value::Null),
        "null (defer) is a combine rule value"
    );
    for field in ["friction_combine", "restitution_combine"] {
        let node = resolve(&root, &properties(def(&root, "material"))[field]);
        assert_eq!(node, rule_node, "{field} uses the combineRule enum");
    }

    let variants: BTreeSet<String> = shape_variants(&root).into_keys().collect();
    let listed = enum_strings(&properties(def(&root, "shape"))["type"]);
    assert_eq!(variants, listed, "shape type enum vs oneOf variants");
    let expected: BTreeSet<String> = ["circle", "box", "polygon", "capsule", "segment", "chain"]
        .into_iter()
        .map(String::from)
        .collect();
    assert_eq!(variants, expected, "shape types the loader knows");

    let joint_kinds: BTreeSet<String> = [JointKind::Revolute]
        .iter()
        .map(|k| {
            match k {
                JointKind::Revolute => {}
            }
            to_value(k).as_str().expect("string").to_string()
        })
        .collect();
    assert_eq!(joint_kinds, enum_strings(&properties(def(&root, "joint"))["type"]));
}

/// Each shape type's fields and required fields in the schema are those the loader takes.
#[test]
fn shape_variants_match_the_loader() {
    let root = schema();
    let variants = shape_variants(&root);
    let all: BTreeSet<String> = variants.values().flat_map(|v| prop_names(v)).collect();
    for (name, variant) in &variants {
        let fields = prop_names(variant);
        let req = required(variant);
        assert!(req.contains("type"), "{name}: type is required");
        let mut base = Map::new();
        base.insert("type".into(), json!(name));
        for f in &req {
            if f != "type" {
                base.insert(f.clone(), sample(f));
            }
        }
        let base = Value::Object(base);
        format::parse(&scene_with_shape(&base)).unwrap_or_else(|e| panic!("{name} with required fields: {e}"));

        // Every optional field of the type is accepted.
        let mut full = base.clone();
        for f in fields.iter().filter(|f| *f != "type") {
            full[f.as_str()] = sample(f);
        }
        format::parse(&scene_with_shape(&full)).unwrap_or_else(|e| panic!("{name} with all its fields: {e}"));

        // Every required field is required.
        for f in req.iter().filter(|f| *f != "type") {
            let mut missing = base.clone();
            missing.as_object_mut().expect("object").remove(f);
            let e = format::parse(&scene_with_shape(&missing)).expect_err("missing required field");
            assert_eq!(e.path, format!("bodies[0].shapes[0].{f}"), "{name} without {f}: {e}");
            assert!(e.message.contains("needs"), "{name} without {f}: {e}");
        }

        // Every field of another type is rejected.
        for f in all.difference(&fields) {
            let mut extra = base.clone();
            extra[f.as_str()] = sample(f);
            let e = format::parse(&scene_with_shape(&extra)).expect_err("field of another type");
            assert_eq!(e.path, format!("bodies[0].shapes[0].{f}"), "{name} with {f}: {e}");
            assert!(e.message.contains("does not apply"), "{name} with {f}: {e}");
        }
    }
}

/// Every "default" in the schema is the value the loader uses when the field is left out.
#[test]
fn schema_defaults_are_the_loader_defaults() {
    let root = schema();
    let parse = |text: String| format::parse(&text).unwrap_or_else(|e| panic!("{text}: {e}"));

    let empty = parse("{}".into());
    for (field, prop) in properties(&root) {
        if let Some(d) = prop.get("default") {
            let got = parse(json!({ field: d }).to_string());
            assert_eq!(got, empty, "scene.{field}: default {d}");
        }
    }

    let empty = parse(json!({ "bodies": [{}] }).to_string());
    for (field, prop) in properties(def(&root, "body")) {
        if let Some(d) = prop.get("default") {
            let got = parse(json!({ "bodies": [{ field: d }] }).to_string());
            assert_eq!(got, empty, "body.{field}: default {d}");
        }
    }

    // Joints, on a scene with a static and a dynamic body.
    let two = json!([{}, { "type": "dynamic" }]);
    let joint = json!({ "body_a": 0, "body_b": 1, "anchor": [0, 0] });
    let empty = parse(json!({ "bodies": two, "joints": [joint] }).to_string());
    for (field, prop) in properties(def(&root, "joint")) {
        if let Some(d) = prop.get("default") {
            let mut with = joint.clone();
            with[field.as_str()] = d.clone();
            let got = parse(json!({ "bodies": two, "joints": [with] }).to_string());
            assert_eq!(got, empty, "joint.{field}: default {d}");
        }
    }
    for (field, prop) in properties(def(&root, "spring")) {
        if let Some(d) = prop.get("default") {
            let spring: SpringSpec = serde_json::from_value(json!({ "hertz": 1, field: d })).expect("spring");
            let plain: SpringSpec = serde_json::from_value(json!({ "hertz": 1 })).expect("spring");
            assert_eq!(spring, plain, "spring.{field}: default {d}");
        }
    }
    for (field, prop) in properties(def(&root, "filter")) {
        if let Some(d) = prop.get("default") {
            let f: FilterSpec = serde_json::from_value(json!({ field: d })).expect("filter");
            assert_eq!(
                tribo::Filter::from(f),
                tribo::Filter::default(),
                "filter.{field}: default {d}"
            );
        }
    }

    for (field, prop) in properties(def(&root, "material")) {
        if let Some(d) = prop.get("default") {
            let spec: MaterialSpec =
                serde_json::from_value(json!({ field: d })).unwrap_or_else(|e| panic!("material.{field}: {e}"));
            assert_eq!(spec.to_material(), Material::default(), "material.{field}: default {d}");
        }
    }

    for (name, variant) in shape_variants(&root) {
        let mut base = json!({ "type": name });
        for f in required(variant).iter().filter(|f| *f != "type") {
            base[f.as_str()] = sample(f);
        }
        let geometry = |shape: &Value| {
            let scene = parse(scene_with_shape(shape));
            let s = &scene.bodies[0].shapes[0];
            (
                scene.shape_geometry("shape", s).expect("valid"),
                scene.shape_material(s),
            )
        };
        let plain = geometry(&base);
        for (field, prop) in properties(variant) {
            if let Some(d) = prop.get("default") {
                let mut with = base.clone();
                with[field.as_str()] = d.clone();
                assert_eq!(geometry(&with), plain, "{name}.{field}: default {d}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// (c) built-in scenes and the documented example use only what the schema knows.

/// Checks `value` against `node`: known keys, required keys, enums, consts, types and
/// numeric ranges (the subset of JSON Schema that the scene schema uses). Collects errors.
fn check(root: &Value, node: &Value, value: &Value, path: &str, errors: &mut Vec<String>) {
    let node = resolve(root, node);
    if let Some(branches) = node.get("oneOf").and_then(Value::as_array) {
        let mut branch_errors = Vec::new();
        let mut matching = 0;
        for b in branches {
            let mut errs = Vec::new();
            check(root, b, value, path, &mut errs);
            if errs.is_empty() {
                matching += 1;
            }
            branch_errors.extend(errs);
        }
        if matching != 1 {
            errors.push(format!("{path}: matches {matching} of the oneOf branches"));
            if matching == 0 {
                errors.extend(branch_errors);
            }
        }
    }
    if let Some(t) = node.get("type").and_then(Value::as_str) {
        let ok = match t {
            "object" => value.is_object(),
            "array" => value.is_array(),
            "string" => value.is_string(),
            "boolean" => value.is_boolean(),
            "number" => value.is_number(),
            "integer" => value.is_u64() || value.is_i64(),
            _ => false,
        };
        if !ok {
            errors.push(format!("{path}: expected {t}, got {value}"));
            return;
        }
    }
    if let Some(options) = node.get("enum").and_then(Value::as_array) {
        if !options.contains(value) {
            errors.push(format!("{path}: {value} is not one of {options:?}"));
        }
    }
    if let Some(c) = node.get("const") {
        if c != value {
            errors.push(format!("{path}: {value} is not {c}"));
        }
    }
    if let Some(x) = value.as_f64() {
        let bound = |k: &str| node.get(k).and_then(Value::as_f64);
        if bound("minimum").is_some_and(|m| x < m)
            || bound("maximum").is_some_and(|m| x > m)
            || bound("exclusiveMinimum").is_some_and(|m| x <= m)
        {
            errors.push(format!("{path}: {x} is out of range"));
        }
    }
    match value {
        Value::Object(m) => {
            for r in required(node) {
                if !m.contains_key(&r) {
                    errors.push(format!("{path}: missing required {r}"));
                }
            }
            let props = node.get("properties").and_then(Value::as_object);
            for (k, v) in m {
                let p = format!("{path}.{k}");
                match (props.and_then(|p| p.get(k)), node.get("additionalProperties")) {
                    (Some(s), _) => check(root, s, v, &p, errors),
                    (None, Some(Value::Bool(false))) => errors.push(format!("{p}: unknown to the schema")),
                    (None, Some(extra)) if extra.is_object() => check(root, extra, v, &p, errors),
                    (None, _) => {}
                }
            }
        }
        Value::Array(a) => {
            let len = a.len() as u64;
            let bound = |k: &str| node.get(k).and_then(Value::as_u64);
            if bound("minItems").is_some_and(|m| len < m) || bound("maxItems").is_some_and(|m| len > m) {
                errors.push(format!("{path}: {len} items is out of range"));
            }
            if let Some(items) = node.get("items") {
                for (i, v) in a.iter().enumerate() {
                    check(root, items, v, &format!("{path}[{i}]"), errors);
                }
            }
        }
        _ => {}
    }
}

fn schema_errors(root: &Value, value: &Value) -> Vec<String> {
    let mut errors = Vec::new();
    check(root, root, value, "scene", &mut errors);
    errors
}

#[test]
fn builtin_scenes_use_only_schema_keys() {
    let root = schema();
    for entry in SCENES.iter().filter(|e| e.name != "many_pyramids") {
        let text = (entry.build)().to_json();
        let value: Value = serde_json::from_str(&text).expect("exported scene is JSON");
        let errors = schema_errors(&root, &value);
        assert!(
            errors.is_empty(),
            "{}: {:#?}",
            entry.name,
            &errors[..errors.len().min(10)]
        );
    }
}

#[test]
fn the_checker_rejects_what_the_schema_forbids() {
    let root = schema();
    let bad = [
        json!({ "bodies": [{ "velocity": [1, 0] }] }),
        json!({ "bodies": [{ "type": "dynamc" }] }),
        json!({ "bodies": [{ "shapes": [{ "type": "circle", "radius": 1, "half_extents": [1, 1] }] }] }),
        json!({ "bodies": [{ "shapes": [{ "type": "circle", "radius": -1 }] }] }),
        json!({ "bodies": [{ "shapes": [{ "type": "capsule", "center1": [0, 0], "radius": 1 }] }] }),
        json!({ "bodies": [{ "shapes": [{ "type": "circle", "radius": 1, "material": { "frction": 1 } }] }] }),
        json!({ "materials": { "m": { "restitution": 1.5 } } }),
        json!({ "materials": { "m": { "friction_combine": "median" } } }),
        json!({ "dt": 0 }),
        json!({ "substeps": 65 }),
        json!({ "gravity": [0, -9.81, 0] }),
        json!({ "bodies": [{}, { "type": "dynamic" }], "joints": [{ "body_a": 0, "body_b": 1 }] }),
        json!({ "bodies": [{}, { "type": "dynamic" }], "joints": [{ "body_a": 0, "body_b": 1, "anchor": [0, 0], "kind": "weld" }] }),
        json!({ "bodies": [{}, { "type": "dynamic" }], "joints": [{ "body_a": 0, "body_b": 1, "anchor": [0, 0], "motor": { "speed": 1, "max_torque": -1 } }] }),
        json!({ "bodies": [{ "shapes": [{ "type": "circle", "radius": 1, "filter": { "category": -1 } }] }] }),
    ];
    for value in bad {
        assert!(
            !schema_errors(&root, &value).is_empty(),
            "schema check accepted {value}"
        );
        assert!(format::parse(&value.to_string()).is_err(), "loader accepted {value}");
    }
}

/// The first ```json block of docs/scene-format.md loads, and fits the schema.
#[test]
fn documented_example_loads_and_fits_the_schema() {
    let start = DOC.find("```json\n").expect("the doc has a ```json example") + "```json\n".len();
    let len = DOC[start..].find("```").expect("the example block is closed");
    let text = &DOC[start..start + len];
    let scene = format::parse(text).unwrap_or_else(|e| panic!("documented example: {e}"));
    scene.build().expect("documented example builds");
    let value: Value = serde_json::from_str(text).expect("JSON");
    let errors = schema_errors(&schema(), &value);
    assert!(errors.is_empty(), "documented example: {errors:#?}");
    // It shows every shape type.
    let types: BTreeSet<&str> = scene
        .bodies
        .iter()
        .flat_map(|b| b.shapes.iter().map(|s| s.kind.as_str()))
        .collect();
    assert_eq!(types.len(), 5, "documented example shows every shape type: {types:?}");
}
