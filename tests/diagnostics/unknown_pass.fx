EFFECT.glow = {
    PASS = {
        brightPass = SHADER.brightPass { img = IN }
        blurX = SHADER.blurX { img = PASS.brightPas }
    }
    OUT = blurY
}
