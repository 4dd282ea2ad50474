INCLUDE "no_such_file.fx"

EFFECT.e = { OUT = IN }
