// Instanced meshes on the GPU: a placement's transforms, unpacked from the records the
// host stores in bvh_nodes. CPU twin: src/accel/instance.rs.

#import types
#import records

//#if INSTANCES
// A placement of an instanced mesh (twin of accel::Instance), unpacked from the two
// bvh_nodes records the host stores it in (instance_records in src/gpu/upload.rs):
// the columns of object_to_world and of world_to_object (the images of x, y and z,
// then the translation), the root node of its mesh's tree, its material, whether it
// mirrors, its index and its mesh's first triangle.
struct Instance {
    o2w_x: vec3<f32>,
    o2w_y: vec3<f32>,
    o2w_z: vec3<f32>,
    o2w_t: vec3<f32>,
    w2o_x: vec3<f32>,
    w2o_y: vec3<f32>,
    w2o_z: vec3<f32>,
    w2o_t: vec3<f32>,
    root: u32,
    material: u32,
    mirrored: bool,
    // Its index among the scene's instances and its mesh's first triangle in
    // `triangles`: a hit named as the CPU names it (HitKey).
    index: u32,
    first_triangle: u32,
}

fn load_instance(record: u32) -> Instance {
    let a = bvh_nodes[record];
    let b = bvh_nodes[record + 1u];
    return Instance(a.origin, bitcast<vec3<f32>>(a.low), bitcast<vec3<f32>>(a.high),
                    bitcast<vec3<f32>>(a.children.xyz),
                    b.origin, bitcast<vec3<f32>>(b.low), bitcast<vec3<f32>>(b.high),
                    bitcast<vec3<f32>>(b.children.xyz),
                    a.exponents, a.spare_low, a.spare_high != 0u, a.children.w, b.exponents);
}

// A mesh-space point in world space.
fn instance_point(instance: Instance, p: vec3<f32>) -> vec3<f32> {
    return instance.o2w_x * p.x + instance.o2w_y * p.y + instance.o2w_z * p.z + instance.o2w_t;
}

// A mesh-space normal in world space, not normalised: through the inverse transpose
// of the linear part, which is the transpose of world_to_object's.
fn instance_normal(instance: Instance, n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(instance.w2o_x, n), dot(instance.w2o_y, n), dot(instance.w2o_z, n));
}

// A mesh-space tangent (w: the bitangent's handedness) in world space: through the
// linear part, renormalised (zero where it vanishes), the handedness flipped under a
// mirroring transform. CPU twin: world_tangent (src/accel/instance.rs).
fn world_tangent(instance: Instance, t: vec4<f32>) -> vec4<f32> {
    let d = instance.o2w_x * t.x + instance.o2w_y * t.y + instance.o2w_z * t.z;
    let length_squared = dot(d, d);
    let direction = select(vec3<f32>(0.0), d * inverseSqrt(length_squared), length_squared > 0.0);
    return vec4<f32>(direction, select(t.w, -t.w, instance.mirrored));
}

// Mesh triangle `index` of instance `record` in world space, as a flattened placement
// stores it: corners moved, corners 1 and 2 swapped under a mirroring transform (which
// keeps the winding normal facing out), the instance's material. CPU twin:
// Instance::world_triangle.
fn instance_world_triangle(index: u32, record: u32) -> Triangle {
    let instance = load_instance(record);
    var triangle = triangles[index];
    let v1 = instance_point(instance, triangle.v1);
    let v2 = instance_point(instance, triangle.v2);
    triangle.v0 = instance_point(instance, triangle.v0);
    triangle.v1 = select(v1, v2, instance.mirrored);
    triangle.v2 = select(v2, v1, instance.mirrored);
    triangle.material = instance.material;
    return triangle;
}
//#endif
