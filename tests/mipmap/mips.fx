// The mip chain of the input (tests/mipmap.rs): levels 1 to 6 side by side on
// top, level 2 sampled explicitly below.
EFFECT.mips = {
    PASS = {
        atlas = SHADER.mip_atlas {
            img = IN
            img.MIPMAP = true
            img.FILTER = nearest
            OUT.FORMAT = rgba8
        }
    }
    OUT = atlas
}
