#pragma once
// Base64 (RFC 4648, section 4: the standard alphabet with '=' padding), for
// binary content carried inside JSON documents (e.g. the images of a
// radiograph pair artifact).

#include <string>
#include <string_view>

namespace mmm {

std::string base64_encode(std::string_view bytes);

// Decodes padded base64; whitespace is not allowed. Throws InvalidInputError
// naming `what` and the offset of the first invalid character, or a length
// that is not a multiple of 4.
std::string base64_decode(std::string_view text, std::string_view what);

}  // namespace mmm
