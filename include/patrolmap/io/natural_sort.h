// Natural ordering of file names: digit runs compare by value, so "2.png"
// sorts before "10.png", and "img9" before "img10".
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace patrolmap::io {

bool NaturalLess(std::string_view a, std::string_view b);
void NaturalSort(std::vector<std::string>* names);

}  // namespace patrolmap::io
