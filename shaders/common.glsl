// What every reconstruction shader starts with: the shared GLSL/C++ headers.
#include "../shared/compat.h"
#include "../shared/params.h"
#include "../shared/screen.h"
