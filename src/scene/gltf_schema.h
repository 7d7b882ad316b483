// The JSON types of a glTF 2.0 document, checked before tinygltf reads it. tinygltf treats a
// property of the wrong type as absent: a node `"translation": [0, "x", 0]` became no
// translation at all, silently. Here every property photonlab reads, and the core schema's
// structural ones, must have the schema's type (number, integer index ≥ 0, string, boolean,
// object, array of so many numbers), or the load fails naming the element, e.g.
//   nodes[1].translation[1]: must be a number, got a string.
// Unknown properties and extensions are not photonlab's business and pass.
#pragma once
#include <string>
#include <vector>

namespace pl {

// The glTF extensions photonlab implements (the loader reads them); any other is ignored, with
// a warning, unless the file requires it.
const std::vector<std::string>& supportedGltfExtensions();

// The document checked before tinygltf reads it, its JSON parsed once. `json` is the document's
// JSON text (a .gltf file, or a .glb's JSON chunk). Returns "" when all is well, else
// "ELEMENT: what is wrong" for the first problem of:
//   - a checked property without its schema type;
//   - an entry of extensionsRequired photonlab does not implement (Draco or meshopt compressed
//     data, say, cannot be read without it: a one-line error naming it, not a broken mesh);
//   - a buffer or image whose URI points to a file that does not exist (`directory`: where
//     relative URIs resolve, percent-decoded; empty for a load from memory, which has none).
// Text that is not JSON passes (the glTF parser reports it).
std::string checkGltfDocument(const std::string& json, const std::string& directory);

}  // namespace pl
