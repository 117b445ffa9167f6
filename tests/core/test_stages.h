// Small stages registered in-process (no plug-in library) for graph and runner tests.
#pragma once

#include "core/pipeline/registry.h"

namespace bimart::test {

// test.source   out value:float            params value=1.0, count=3, extra (YAML text)
// test.double   in value:float -> out value:float (x2)
// test.sink     in value:float, optional extra:string -> out result:string
// test.text     out value:string
// test.random   out draws:int list          param count=4
// test.lazy     out value:float, never written
// test.strict   param positive=1 (constructor throws if <= 0), out value:float
// test.cycle_a  in a:float -> out b:float ; test.cycle_b in b:float -> out a:float
Registry make_registry();

}  // namespace bimart::test
