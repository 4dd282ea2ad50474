EFFECT.glow = {
    PASS = {
        brightPass = SHADER.brightPass {
            img = IN
        }
        blurX = SHADER.blurX {
            img = PASS.brightPass
            OUT.SCALE = (0.5, 0.5)
        }
        blurY = SHADER.blurY {
            img = PASS.blurX
            OUT.SCALE = (0.5, 0.5)
        }
        final = SHADER.add {
            img1 = IN
            img2 = PASS.blurY
        }
    }
    OUT = final
}
