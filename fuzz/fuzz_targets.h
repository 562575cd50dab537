#pragma once
// The fuzz targets, one function each, all linked into one executable
// (mmm_fuzz) that runs the one named by $MMM_FUZZ_TARGET: one link of the
// libraries instead of one per target.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace mmm::fuzz {

using Target = void (*)(const std::uint8_t* data, std::size_t size);

void stl(const std::uint8_t* data, std::size_t size);
void ply(const std::uint8_t* data, std::size_t size);
void obj(const std::uint8_t* data, std::size_t size);
void off(const std::uint8_t* data, std::size_t size);
void vtp(const std::uint8_t* data, std::size_t size);
void trc(const std::uint8_t* data, std::size_t size);
void mot(const std::uint8_t* data, std::size_t size);
void osim(const std::uint8_t* data, std::size_t size);
void workflow_yaml(const std::uint8_t* data, std::size_t size);
void atlas_manifest(const std::uint8_t* data, std::size_t size);
void atlas_recipe(const std::uint8_t* data, std::size_t size);
void markups(const std::uint8_t* data, std::size_t size);
void submission(const std::uint8_t* data, std::size_t size);
void views(const std::uint8_t* data, std::size_t size);
void png(const std::uint8_t* data, std::size_t size);
void dicom(const std::uint8_t* data, std::size_t size);
void deidentified(const std::uint8_t* data, std::size_t size);

}  // namespace mmm::fuzz
