// What the HLSL programs around a user's function start with: the shared
// headers, compiled as HLSL (shared/compat.h).
#define DB_HLSL 1
#include "../../shared/compat.h"
#include "../../shared/params.h"
#include "../../shared/screen.h"
