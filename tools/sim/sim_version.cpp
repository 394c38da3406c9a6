// Anchors the sim library so it links even while a build has no other sim sources.
namespace docksim { extern const char* const kSimVersion; const char* const kSimVersion = "1"; }
