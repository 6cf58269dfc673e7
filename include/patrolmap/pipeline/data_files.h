// Where the front ends find the files patrolmap ships (the default vocabulary), so the binaries work
// from any folder: the build tree, an install prefix, or a place named by an environment variable.
#pragma once

#include <string>

#include "patrolmap/core/status.h"

namespace patrolmap::pipeline {

// The environment variable that names the default vocabulary file.
constexpr const char* kVocabularyVariable = "PATROLMAP_VOCABULARY";

// Finds the default vocabulary, trying in order:
//  1. $PATROLMAP_VOCABULARY;
//  2. beside the executable: <exe>/../share/patrolmap/default.pmvoc (an install prefix), and the
//     source tree the executable was built from (<source>/vocab/default.pmvoc);
//  3. the install prefix configured at build time (<prefix>/share/patrolmap/default.pmvoc).
// Fails naming every place it looked.
Status FindDefaultVocabulary(std::string* path);

}  // namespace patrolmap::pipeline
