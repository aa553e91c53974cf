// Replaces libtet's weak terminatetetgen(). Debian's version frees the mesh before throwing
// and double-frees on self-intersecting input; throwing the code lets the caller clean up.
// This file must not include tetgen.h (its inline declaration would clash).
class tetgenmesh;

void terminatetetgen(tetgenmesh* /*mesh*/, int code) { throw code; }
