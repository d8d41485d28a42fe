#pragma once
/// @file
/// Errors that blame what the user typed: a front-end (a CLI flag, a deployment's option) sets a
/// library parameter under another name, and the library's mc::InvalidParams names its field.
/// `naming_fields` re-throws such an error with the field replaced by the name the user gave.

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace mc {

/// Runs `work`; an mc::InvalidParams is re-thrown as an mc::Error with the same exit code (3) and
/// each whole field named in `field_to_name` ({"lead_m", "--lead"}) replaced by its name. A field
/// matches as a whole word (letters, digits, '_', '.'), or as the head of a dotted path. Other
/// exceptions pass unchanged.
void naming_fields(const std::vector<std::pair<std::string, std::string>>& field_to_name,
                   const std::function<void()>& work);

}  // namespace mc
