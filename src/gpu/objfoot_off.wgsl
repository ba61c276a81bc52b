// Stand-ins for objfoot.wgsl in a variant without OBJECT_FOOTPRINT: its
// calls stand behind that switch and are never made (see
// footprint_off.wgsl).

fn objfp_crossings(seg: Seg, s: f32, last_z: f32) -> u32 {
    return 0u;
}

fn object_footprint(i: u32, seg: Seg, hit: ObjHit) {
    obj_fp.ok = false;
}
