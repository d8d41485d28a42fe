#include "microcobot/core/field_names.h"

#include <cctype>

#include "microcobot/core/error.h"

namespace mc {

void naming_fields(const std::vector<std::pair<std::string, std::string>>& field_to_name,
                   const std::function<void()>& work) {
  try {
    work();
  } catch (const InvalidParams& e) {
    std::string text = e.what();
    const auto word = [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.';
    };
    for (const auto& [field, name] : field_to_name) {
      for (std::size_t pos = 0; (pos = text.find(field, pos)) != std::string::npos;) {
        const std::size_t end = pos + field.size();
        if ((pos > 0 && word(text[pos - 1])) || (end < text.size() && word(text[end]) && text[end] != '.')) {
          pos = end;
          continue;
        }
        text.replace(pos, field.size(), name);
        pos += name.size();
      }
    }
    throw Error(e.exit_code(), text);
  }
}

}  // namespace mc
