// An implicit-level sample of a mipmapped input at a quarter of its size
// (tests/mipmap.rs): level 2.
EFFECT.lod = {
    PASS = {
        quarter = SHADER.mip_lod {
            img = IN
            img.MIPMAP = true
            img.FILTER = nearest
            OUT.SCALE = 0.25
            OUT.FORMAT = rgba8
        }
    }
    OUT = quarter
}
