// gltf_materials.cpp — glTF materials → gpu::Material, and the textures they reference.
//
// Covered: the core metallic-roughness model (glTF 2.0 §3.9.2), emission (§3.9.3) with
// KHR_materials_emissive_strength, KHR_materials_specular, KHR_materials_ior, alpha modes
// (§3.9.4) and doubleSided (§3.9.5). Everything else a material uses is reported through
// Context::unsupported.
#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/gltf_internal.h"

namespace gdpt::gltf {
namespace {

const std::string kEmissiveStrength = "KHR_materials_emissive_strength";
const std::string kSpecular = "KHR_materials_specular";
const std::string kIor = "KHR_materials_ior";

double numberOr(const tinygltf::Value& obj, const char* key, double fallback) {
    if (!obj.IsObject() || !obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsNumber()) throw Error(std::string("'") + key + "' is not a number");
    return v.GetNumberAsDouble();
}

glm::vec3 vec3Or(const tinygltf::Value& obj, const char* key, glm::vec3 fallback) {
    if (!obj.IsObject() || !obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 3)
        throw Error(std::string("'") + key + "' is not an array of 3 numbers");
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) {
        if (!v.Get(i).IsNumber()) throw Error(std::string("'") + key + "' is not an array of 3 numbers");
        out[i] = static_cast<float>(v.Get(i).GetNumberAsDouble());
    }
    return out;
}

// A material factor as a float after checking that it lies in [lo, hi]. The glTF 2.0 schema
// bounds every factor (material.schema.json, material.pbrMetallicRoughness.schema.json and
// the extensions'); a value outside, or NaN, would give negative, NaN or energy-gaining
// radiance, so the file is refused rather than clamped.
float checkedFactor(double v, double lo, double hi, const std::string& what) {
    if (!(v >= lo && v <= hi) || !std::isfinite(v))
        throw Error(what + " is " + formatNumber(v) + ", outside [" + formatNumber(lo) + ", " +
                    (std::isinf(hi) ? std::string("inf)") : formatNumber(hi) + "]") + " (glTF 2.0 schema)");
    return static_cast<float>(v);
}

// Component c of factor `name` (an array), checked as by checkedFactor.
float checkedComponent(const std::vector<double>& v, std::size_t c, double lo, double hi, const char* name) {
    return checkedFactor(v[c], lo, hi, std::string(name) + " component " + std::to_string(c));
}

constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// Resolves a texture reference to an index into scene.textures, decoding the image on
// first use in the requested colour space. Returns -1 when the texture cannot be used.
int resolveTexture(Context& ctx, int textureIndex, int texCoord, const tinygltf::ExtensionMap& infoExtensions,
                   bool srgb, const std::string& slot) {
    if (textureIndex < 0) return -1;
    const tinygltf::Model& model = ctx.model;
    if (static_cast<std::size_t>(textureIndex) >= model.textures.size())
        throw Error(slot + ": texture " + std::to_string(textureIndex) + " out of range (file has " +
                    std::to_string(model.textures.size()) + " textures)");
    if (texCoord != 0) {
        // Using TEXCOORD_0 instead would map the texture wrongly; drop it and say so.
        ctx.unsupported(slot + " uses TEXCOORD_" + std::to_string(texCoord) +
                        " (only TEXCOORD_0); texture ignored");
        return -1;
    }
    for (const auto& [name, value] : infoExtensions) {
        (void)value;
        ctx.unsupported(name + " on " + slot + " (texture used untransformed)");
    }
    const auto key = std::make_pair(textureIndex, srgb);
    if (auto it = ctx.textureCache.find(key); it != ctx.textureCache.end()) return it->second;

    const tinygltf::Texture& tex = model.textures[static_cast<std::size_t>(textureIndex)];
    const std::string texLabel = elementName("texture", textureIndex, tex.name);
    if (tex.sampler >= 0) {
        if (static_cast<std::size_t>(tex.sampler) >= model.samplers.size())
            throw Error(texLabel + ": sampler " + std::to_string(tex.sampler) + " out of range");
        const tinygltf::Sampler& s = model.samplers[static_cast<std::size_t>(tex.sampler)];
        // The kernels always wrap with REPEAT (the glTF default, §5.26 "sampler").
        if (s.wrapS != TINYGLTF_TEXTURE_WRAP_REPEAT || s.wrapT != TINYGLTF_TEXTURE_WRAP_REPEAT)
            ctx.unsupported("sampler " + std::to_string(tex.sampler) +
                            ": wrap modes other than REPEAT (REPEAT used)");
    }
    if (tex.source < 0) {
        ctx.unsupported(texLabel +
                        " has no PNG/JPEG source (e.g. KHR_texture_basisu, "
                        "EXT_texture_webp); texture ignored");
        return -1;
    }
    if (static_cast<std::size_t>(tex.source) >= model.images.size())
        throw Error(texLabel + ": image " + std::to_string(tex.source) + " out of range (file has " +
                    std::to_string(model.images.size()) + " images)");
    const tinygltf::Image& img = model.images[static_cast<std::size_t>(tex.source)];
    const std::string imgName = img.name.empty() ? img.uri : img.name;
    // data: URIs are not names; keep messages short.
    const bool printable = !imgName.empty() && imgName.size() <= 80 && imgName.rfind("data:", 0) != 0;
    const std::string imgLabel =
        "image " + std::to_string(tex.source) + (printable ? " '" + imgName + "'" : "");
    if (img.image.empty() || img.width <= 0 || img.height <= 0)
        throw Error(imgLabel + " could not be loaded or decoded");
    Texture out = imageToTexture(img, srgb);
    out.name =
        (printable ? imgName : "image " + std::to_string(tex.source)) + (srgb ? " (sRGB)" : " (linear)");
    ctx.scene.textures.push_back(std::move(out));
    const int index = static_cast<int>(ctx.scene.textures.size() - 1);
    ctx.textureCache[key] = index;
    return index;
}

gpu::Material convertMaterial(Context& ctx, const tinygltf::Material& m) {
    gpu::Material out{};
    const auto& pbr = m.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() != 4) throw Error("baseColorFactor must have 4 numbers");
    for (std::size_t c = 0; c < 4; ++c)
        out.baseColor[static_cast<int>(c)] =
            checkedComponent(pbr.baseColorFactor, c, 0.0, 1.0, "baseColorFactor");
    out.metallic = checkedFactor(pbr.metallicFactor, 0.0, 1.0, "metallicFactor");
    out.roughness = checkedFactor(pbr.roughnessFactor, 0.0, 1.0, "roughnessFactor");
    out.baseColorTex = resolveTexture(ctx, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                      pbr.baseColorTexture.extensions, true, "baseColorTexture");
    out.metallicRoughnessTex =
        resolveTexture(ctx, pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                       pbr.metallicRoughnessTexture.extensions, false, "metallicRoughnessTexture");

    // Emission: emissiveFactor × KHR_materials_emissive_strength = radiance.
    // Emission above 1 needs the extension: emissiveFactor is in [0, 1].
    if (m.emissiveFactor.size() != 3) throw Error("emissiveFactor must have 3 numbers");
    for (std::size_t c = 0; c < 3; ++c) checkedComponent(m.emissiveFactor, c, 0.0, 1.0, "emissiveFactor");
    double strength = 1.0;
    if (auto it = m.extensions.find(kEmissiveStrength); it != m.extensions.end())
        strength = numberOr(it->second, "emissiveStrength", 1.0);
    if (!(strength >= 0.0) || !std::isfinite(strength))
        throw Error("emissiveStrength " + formatNumber(strength) + " is not a finite value >= 0");
    out.emissive = glm::vec3(static_cast<float>(m.emissiveFactor[0] * strength),
                             static_cast<float>(m.emissiveFactor[1] * strength),
                             static_cast<float>(m.emissiveFactor[2] * strength));
    if (!std::isfinite(out.emissive.x) || !std::isfinite(out.emissive.y) || !std::isfinite(out.emissive.z))
        throw Error("emissiveFactor x emissiveStrength " + formatNumber(strength) +
                    " overflows single precision");
    out.emissiveTex = resolveTexture(ctx, m.emissiveTexture.index, m.emissiveTexture.texCoord,
                                     m.emissiveTexture.extensions, true, "emissiveTexture");

    // KHR_materials_specular defaults: specularFactor 1, specularColorFactor (1,1,1).
    out.specular = 1.0f;
    out.specularColor = glm::vec3(1.0f);
    if (auto it = m.extensions.find(kSpecular); it != m.extensions.end()) {
        out.specular = checkedFactor(numberOr(it->second, "specularFactor", 1.0), 0.0, 1.0, "specularFactor");
        out.specularColor = vec3Or(it->second, "specularColorFactor", glm::vec3(1.0f));
        // material.KHR_materials_specular.schema.json: components >= 0, no upper bound.
        for (int c = 0; c < 3; ++c)
            checkedFactor(out.specularColor[c], 0.0, kUnbounded,
                          "specularColorFactor component " + std::to_string(c));
        if (it->second.Has("specularTexture") || it->second.Has("specularColorTexture"))
            ctx.unsupported("KHR_materials_specular textures (factors used)");
    }
    // KHR_materials_ior: default 1.5; 0 is allowed by the extension (meaning "infinite").
    out.ior = 1.5f;
    if (auto it = m.extensions.find(kIor); it != m.extensions.end()) {
        const double ior = numberOr(it->second, "ior", 1.5);
        if (!(ior == 0.0 || (ior >= 1.0 && std::isfinite(ior))))
            throw Error("ior " + formatNumber(ior) +
                        " is neither 0 nor a finite value >= 1 (KHR_materials_ior)");
        out.ior = static_cast<float>(ior);
    }

    out.flags = 0;
    out.alphaCutoff = 0.5f;
    if (m.alphaMode == "MASK") {
        out.flags |= gpu::kMatFlagAlphaMask;
        out.alphaCutoff = checkedFactor(m.alphaCutoff, 0.0, kUnbounded, "alphaCutoff");
    } else if (m.alphaMode == "BLEND") {
        ctx.unsupported("alphaMode BLEND (rendered opaque)");
    } else if (m.alphaMode != "OPAQUE" && !m.alphaMode.empty()) {
        throw Error("alphaMode '" + m.alphaMode + "' is not OPAQUE, MASK or BLEND");
    }
    if (m.doubleSided) out.flags |= gpu::kMatFlagDoubleSided;
    if (glm::any(glm::greaterThan(out.emissive, glm::vec3(0.0f)))) out.flags |= gpu::kMatFlagEmissive;

    out.normalTex = resolveTexture(ctx, m.normalTexture.index, m.normalTexture.texCoord,
                                   m.normalTexture.extensions, false, "normalTexture");
    if (m.normalTexture.index >= 0) ctx.unsupported("normal textures are ignored");
    if (m.occlusionTexture.index >= 0)
        ctx.unsupported("occlusionTexture ignored (the path tracer computes occlusion)");
    for (const auto& [name, value] : m.extensions) {
        (void)value;
        if (name != kEmissiveStrength && name != kSpecular && name != kIor)
            ctx.unsupported("material extension " + name);
    }
    return out;
}

// The default material of glTF 2.0 §3.9.6 / §5.19: baseColor 1, metallic 1, roughness 1,
// no emission, opaque, single-sided; extension defaults for specular and ior.
gpu::Material defaultGltfMaterial() {
    gpu::Material m{};
    m.baseColor = glm::vec4(1.0f);
    m.metallic = 1.0f;
    m.roughness = 1.0f;
    m.specular = 1.0f;
    m.specularColor = glm::vec3(1.0f);
    m.ior = 1.5f;
    m.alphaCutoff = 0.5f;
    m.flags = 0;
    m.baseColorTex = m.metallicRoughnessTex = m.emissiveTex = m.normalTex = -1;
    return m;
}

}  // namespace

void convertMaterials(Context& ctx) {
    const auto& mats = ctx.model.materials;
    ctx.scene.materials.reserve(mats.size());
    for (std::size_t i = 0; i < mats.size(); ++i) {
        try {
            ctx.scene.materials.push_back(convertMaterial(ctx, mats[i]));
        } catch (const Error& e) {
            throw e.withContext(elementName("material", static_cast<int>(i), mats[i].name));
        }
    }
}

std::uint32_t materialIndex(Context& ctx, int material) {
    if (material < 0) {
        if (ctx.defaultMaterial < 0) {
            ctx.scene.materials.push_back(defaultGltfMaterial());
            ctx.defaultMaterial = static_cast<int>(ctx.scene.materials.size() - 1);
        }
        return static_cast<std::uint32_t>(ctx.defaultMaterial);
    }
    if (static_cast<std::size_t>(material) >= ctx.model.materials.size())
        throw Error("material " + std::to_string(material) + " out of range (file has " +
                    std::to_string(ctx.model.materials.size()) + " materials)");
    // convertMaterials ran first, so glTF material i is scene material i.
    return static_cast<std::uint32_t>(material);
}

}  // namespace gdpt::gltf
