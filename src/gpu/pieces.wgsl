// The pieces' loop: twin of src/transfer/pieces.rs, one loop for the
// visible band's gas (gas.wgsl's v_take) and the physical media
// (transfer.wgsl's m_take), whichever the variant holds (MEDIUM). A
// stretch is cut into `pieces` pieces, thinner where one is thicker than
// MAX_DTAU at some wavelength or frequency, the next growing back by at
// most 2; a piece ends at a surface of the medium (m_cut); the walk ends
// where the gas has spent the ray (below SPENT everywhere).

// How many pieces a stretch `len` long gets where its gas changes over
// `scale` (pieces::count).
fn pieces_count(len: f32, scale: f32) -> f32 {
    return clamp(ceil(len / (SCALE_FRACTION * scale)), 1.0, MAX_PIECES);
}

// Whether nothing further along can be seen any more.
fn pieces_spent() -> bool {
    if MEDIUM {
        return !m_alive;
    }
    return through < SPENT;
}

// Takes the piece from s to e of `seg` (Pieces::take): its greatest
// optical depth, or minus it where it asks to be cut thinner.
fn piece_take(seg: Seg, s: f32, e: f32, finest: bool) -> f32 {
    if MEDIUM {
        return m_take(seg, s, e, finest);
    }
    return v_take(seg, s, e, finest);
}

// pieces::walk from s0 to s1 of `seg` in `pieces` pieces.
fn pieces_walk(seg: Seg, s0: f32, s1: f32, pieces: f32) {
    let base_ds = (s1 - s0) / pieces;
    var ds = base_ds;
    let min_ds = (s1 - s0) / MAX_PIECES;
    var s = s0;
    var r_start = 0.0;
    // A surface inside the medium (Pieces::level): pieces end where its
    // level crosses 1, and are told when they touch it or come NEAR.
    var levelled = false;
    var level_start = 0.0;
    var starts_at_edge = false;
    if MEDIUM {
        r_start = m_at(seg, s0).x;
        levelled = medium_sharp();
        if levelled {
            level_start = m_level(seg, s0);
        }
        m_edge = false;
    }
    var guard = 0u;
    while s < s1 && !pieces_spent() && guard < 4000000u {
        guard += 1u;
        var e = min(s + ds, s1);
        var r_e = r_start;
        var level_e = level_start;
        if MEDIUM {
            let cut = m_cut(seg, s, e, r_start, min_ds);
            e = cut.x;
            r_e = cut.y;
            if levelled {
                level_e = m_level(seg, e);
                let ends_at_edge = (level_e > 1.0) != (level_start > 1.0);
                // A crossing within half the finest piece of the start is
                // the one just passed (f32 may see it again): the piece
                // is taken whole.
                if ends_at_edge {
                    let c = m_level_change(seg, s, e, level_start > 1.0);
                    if c - s > 0.5 * min_ds {
                        e = c;
                        level_e = m_level(seg, e);
                        r_e = m_at(seg, e).x;
                    }
                }
                m_edge = ends_at_edge || starts_at_edge || max(level_start, level_e) > NEAR;
            }
        }
        let depth = piece_take(seg, s, e, ds <= min_ds);
        if depth < 0.0 {
            ds = min(max(ds * MAX_DTAU / -depth, min_ds), 0.5 * ds);
        } else {
            s = e;
            r_start = r_e;
            if levelled {
                starts_at_edge = (level_e > 1.0) != (level_start > 1.0);
                level_start = level_e;
            }
            var grow = 2.0;
            if depth > 0.0 {
                grow = clamp(0.8 * MAX_DTAU / depth, 1.0, 2.0);
            }
            ds = min(ds * grow, base_ds);
        }
    }
}
