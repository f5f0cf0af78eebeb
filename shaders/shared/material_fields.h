// A material's fields, one row each, and every user of a field reads it from its row:
// retile/scene.h declares the member, the native reader and writer, validation, edits and the
// properties panel iterate the rows (kMaterialScalars, kMaterialColors, kMaterialTextures,
// kMaterialChoices) and packMaterial writes the value to its slot. The kernel reads a scalar or a
// texture there by name (kMaterialSlot_<member>); a colour through the texels unpackMaterial
// takes (render_materials.cpp asserts the packed ones' texels). A new field is a row here, the
// GLSL that reads it and a test. Included by C++ (retile/scene.h) and GLSL (shared/layouts.h),
// each defining all four RETILE_MATERIAL_* first: no include guard.
//
// RETILE_MATERIAL_SCALAR(member, key, default, lo, hi, types, texel, component, label, unit, decimals, atLo, place, tip)
//   member            Material's float member
//   key               its key in native files (written when it differs from the default)
//   default, lo, hi   a new material's value, and the range every reader and editor keeps it in
//   types             the types it applies to: RT_TYPE(Hair) | ..., or RT_ALL_TYPES (a boundary has
//                     no surface: nothing of one applies to it)
//   texel, component  where packMaterial writes it, clamped to the range, for those types (other
//                     types may use the slot for another field); -1, -1: packed by code
//                     (render_materials.cpp), where the kernel wants it transformed
//   label, unit, decimals  the properties panel's row ("" no unit)
//   atLo              what the panel shows at lo instead of the number, where lo means the
//                     field's effect is absent ("none"); "" the number
//   place             where the panel shows it: RT_PANEL(Surface) for its types, Rough beside the
//                     roughness, Coated while the material has a coat, Emissive while it emits,
//                     Bumped beside a bump texture; Custom: the panel draws it itself (a slider, a
//                     compound widget, a label that depends on the type)
//   tip               the panel row's tooltip ("" none)
//
// RETILE_MATERIAL_COLOR(member, key, r, g, b, hi, types, texel, label, widget, place, tip)
//   member, key       Material's Vec3 member, its key in native files (written when not the default)
//   r, g, b           a new material's value
//   hi                the most a channel may be; each is finite and at least 0
//   types, texel      as a scalar's: packMaterial writes the colour, clamped, to the texel's xyz for
//                     its types; -1: packed by code
//   label, widget     the panel's row: RT_WIDGET(Swatch) a colour picker, Channels three fields for
//                     values beyond 1
//   place, tip        as a scalar's
//
// RETILE_MATERIAL_TEXTURE(member, key, types, texel, component, label, place)
//   A texture that feeds an input (kNoNode: none). packMaterial writes its index (-1 none) to the
//   slot for its types and -1 for the others: the slot is the texture's for every type. The
//   kernel reads it as RT_MATERIAL_TEXTURE(m, member).
//
// RETILE_MATERIAL_CHOICE(member, key, off, on, types, flag, label, offLabel, onLabel, place, tip)
//   A bool member, written to files as `key: on` when set (`off` or no key: not set). For its
//   types packMaterial sets kMat<flag> in the type texel, which the kernel tests.

// Microfacet alpha for rough types, sigma for Oren-Nayar (which alone goes past 1), Phong's lobe
// width, hair's cones' width (its R lobe's angular deviation is pi / 2 times it, at least 0.04).
RETILE_MATERIAL_SCALAR(roughness, "roughness", 0.1, 0.0, 1.6,
                       RT_TYPE(RoughPlastic) | RT_TYPE(RoughConductor) | RT_TYPE(RoughDielectric) | RT_TYPE(OrenNayar) | RT_TYPE(Phong) |
                           RT_TYPE(Hair),
                       -1, -1, "Roughness", "", 3, "", RT_PANEL(Custom), "")
// The dielectric's index: a plastic's coating, glass, a thin sheet. Below 1 is an interface seen
// from the denser side (air bubbles in ice).
RETILE_MATERIAL_SCALAR(ior, "ior", 1.5, 0.1, 10.0,
                       RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(ThinSheet),
                       -1, -1, "IOR", "", 3, "", RT_PANEL(Surface), "")
// A clear coat over an opaque type: a smooth dielectric layer of this index (1: none)
// that reflects by Fresnel and through which the material is seen with both directions
// refracted. No light bounces between the coat and what it covers.
RETILE_MATERIAL_SCALAR(coatIor, "coat_ior", 1.0, 1.0, 10.0,
                       RT_TYPE(Lambert) | RT_TYPE(OrenNayar) | RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Conductor) |
                           RT_TYPE(RoughConductor) | RT_TYPE(Mirror) | RT_TYPE(Null) | RT_TYPE(Phong),
                       -1, -1, "Coat IOR", "", 3, "none", RT_PANEL(Surface), "A clear coat over the material: a dielectric layer of this index; none at 1")
// Above 0, the coat is rough: its reflection a GGX lobe of this alpha (Smith's G as the product
// of both G1), and what is below seen as through the smooth coat times cos wo / cos wo' (wo toward
// the viewer, wo' inside), which darkens the base at grazing views and is not reciprocal.
RETILE_MATERIAL_SCALAR(coatRoughness, "coat_roughness", 0.0, 0.0, 1.0,
                       RT_TYPE(Lambert) | RT_TYPE(OrenNayar) | RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Conductor) |
                           RT_TYPE(RoughConductor) | RT_TYPE(Mirror) | RT_TYPE(Null) | RT_TYPE(Phong),
                       -1, -1, "Coat roughness", "", 3, "", RT_PANEL(Coated), "")
// Phong: the share of albedo reflected as Lambert, in the slot plastics keep their coating's
// internal reflectance in.
RETILE_MATERIAL_SCALAR(diffuseRatio, "diffuse_ratio", 0.2, 0.0, 1.0, RT_TYPE(Phong), 1, 3, "Diffuse ratio", "", 3, "", RT_PANEL(Surface), "")
// Diffuse transmission: the share of albedo passed through, in the same slot.
RETILE_MATERIAL_SCALAR(transmittance, "transmittance", 0.5, 0.0, 1.0, RT_TYPE(DiffuseTransmission), 1, 3, "Transmittance", "", 3,
                       "", RT_PANEL(Surface), "")
// Hair: the angle by which its cuticle's scales tilt the lobes: R by -2 of it, TT by 1 and TRT by
// 4. In the slot conductors keep eta's red.
RETILE_MATERIAL_SCALAR(hairTilt, "hair_tilt", 2.0, -45.0, 45.0, RT_TYPE(Hair), 2, 0, "Scale tilt", "degrees", 1, "", RT_PANEL(Surface),
                       "How far the cuticle's scales lean the highlights along the fibre: the white one towards the tip, the coloured one back")
// Thin sheets: thin-film interference over a film this thick: the sheet's reflectance then
// varies by channel (red, green and blue taken at 650, 510 and 475 nm) and with the angle. 0:
// none. A sheet has no roughness: the film takes its slot, and a roughness texture scales it.
RETILE_MATERIAL_SCALAR(filmThickness, "film_thickness", 0.0, 0.0, 1e5, RT_TYPE(ThinSheet), 1, 0, "Film thickness", "nm", 1,
                       "none", RT_PANEL(Surface), "Thin-film interference over a film this thick: colours that change with the angle, as on a soap bubble; 0 for none")
// Glass or a boundary filled with a medium: the asymmetry of its Henyey-Greenstein phase
// function (-1 back, 0 even, 1 forward).
RETILE_MATERIAL_SCALAR(interiorAnisotropy, "interior_anisotropy", 0.0, -0.99, 0.99,
                       RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(Boundary), 9, 3, "Interior anisotropy", "", 2,
                       "", RT_PANEL(Custom), "")
// Coverage: below 1 (or with an alpha texture) the surface is a cut-out.
RETILE_MATERIAL_SCALAR(alpha, "alpha", 1.0, 0.0, 1.0, RT_ALL_TYPES & ~RT_TYPE(Boundary), 1, 2, "Alpha", "", 3, "", RT_PANEL(Surface), "")
// Scales the slope of the bump texture's value.
RETILE_MATERIAL_SCALAR(bumpStrength, "bump_strength", 1.0, -1e4, 1e4, RT_ALL_TYPES & ~RT_TYPE(Boundary), 5, 1, "Bump strength", "", 3, "", RT_PANEL(Bumped), "")
// The front's emitted radiance is emission times this: at 0 the light is off and keeps its colour.
RETILE_MATERIAL_SCALAR(emissionStrength, "emission_strength", 1.0, 0.0, 1e6, RT_ALL_TYPES & ~RT_TYPE(Boundary), -1, -1, "Emission", "", 2, "", RT_PANEL(Custom),
                       "")
// The half-angle about the front's normal of the cone the front emits into: 90 is the whole
// hemisphere; less, a spot with a hard edge. Seen from outside the cone the emitter is dark, and
// light samples from there find nothing.
RETILE_MATERIAL_SCALAR(emissionCone, "emission_cone", 90.0, 0.0, 90.0, RT_ALL_TYPES & ~RT_TYPE(Boundary), -1, -1, "Emission cone", "degrees", 1,
                       "", RT_PANEL(Emissive),
                       "The half-angle about the normal within which the front emits: 90 lights the whole hemisphere, less makes a spot with a hard edge")
// A blend's share of this material (Material::blendWith), the partner's the rest.
RETILE_MATERIAL_SCALAR(blendRatio, "blend_ratio", 1.0, 0.0, 1.0, RT_ALL_TYPES & ~RT_TYPE(Boundary), 6, 3, "Blend ratio", "", 3, "", RT_PANEL(Custom), "")

// What the surface reflects (and, for glass, passes). Hair's colour is its pigment's absorption,
// but its albedo is the denoiser's guide there; the panel draws it (not for hair).
RETILE_MATERIAL_COLOR(albedo, "albedo", 0.8, 0.8, 0.8, 1e6, RT_ALL_TYPES & ~RT_TYPE(Boundary), 0, "Albedo", RT_WIDGET(Swatch),
                      RT_PANEL(Custom), "")
// The front's emitted radiance is emission times emissionStrength: the colour, and a strength
// that at 0 turns the light off and keeps its colour (importers leave the strength at 1). Packed
// as their product.
RETILE_MATERIAL_COLOR(emission, "emission", 0.0, 0.0, 0.0, 1e30, RT_ALL_TYPES & ~RT_TYPE(Boundary), -1, "Emission colour",
                      RT_WIDGET(Swatch), RT_PANEL(Custom), "")
// Plastics: the coating's absorption, its sigma_a times its thickness: the diffuse base shows
// through dimmed by exp(-a (1 / cos wi + 1 / cos wo)). Thin sheets: the sheet's, light passing
// through it dimmed by exp(-a / cos t), t the angle inside the sheet. Hair: its pigment's, per
// unit of the fibre's radius. The panel names it by the type.
RETILE_MATERIAL_COLOR(coatingAbsorption, "coating_absorption", 0.0, 0.0, 0.0, 1e6,
                      RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(ThinSheet) | RT_TYPE(Hair), 6, "Coating absorption",
                      RT_WIDGET(Channels), RT_PANEL(Custom), "")
// The clear coat's (coatIor): what is below is seen dimmed by exp(-a (1 / cos + 1 / cos)), sigma_a
// times thickness. Shares its texel with a medium's absorption (glass takes no coat).
RETILE_MATERIAL_COLOR(coatAbsorption, "coat_absorption", 0.0, 0.0, 0.0, 1e6,
                      RT_TYPE(Lambert) | RT_TYPE(OrenNayar) | RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Conductor) |
                          RT_TYPE(RoughConductor) | RT_TYPE(Mirror) | RT_TYPE(Null) | RT_TYPE(Phong),
                      -1, "Coat absorption", RT_WIDGET(Channels), RT_PANEL(Coated), "")
// Glass, or a boundary filled with a homogeneous medium: per unit of length what fills it absorbs
// and scatters (by interiorAnisotropy's phase function). Light that only crosses it is dimmed by
// exp(-(absorption + scattering) distance). A path remembers one medium outside the one it is in:
// glass in fog leaves the fog around it, but a third level of nesting is not tracked. Packed only
// where the material holds a medium (Material::filled).
RETILE_MATERIAL_COLOR(interiorAbsorption, "interior_absorption", 0.0, 0.0, 0.0, 1e6,
                      RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(Boundary), -1, "Interior absorption",
                      RT_WIDGET(Channels), RT_PANEL(Custom), "")
RETILE_MATERIAL_COLOR(interiorScattering, "interior_scattering", 0.0, 0.0, 0.0, 1e6,
                      RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(Boundary), -1, "Interior scattering",
                      RT_WIDGET(Channels), RT_PANEL(Custom), "")
// A conductor's complex index of refraction when its metal is "custom" (else the named metal's,
// which packMaterial looks up).
RETILE_MATERIAL_COLOR(eta, "eta", 0.2, 0.92, 1.1, 1e3, RT_TYPE(Conductor) | RT_TYPE(RoughConductor), -1, "Eta", RT_WIDGET(Channels),
                      RT_PANEL(Custom), "")
RETILE_MATERIAL_COLOR(k, "k", 3.9, 2.45, 2.14, 1e3, RT_TYPE(Conductor) | RT_TYPE(RoughConductor), -1, "K", RT_WIDGET(Channels),
                      RT_PANEL(Custom), "")

// Multiplies albedo (glTF's baseColorTexture). Hair takes its colour from its pigment.
RETILE_MATERIAL_TEXTURE(albedoTexture, "albedo_texture", RT_ALL_TYPES & ~RT_TYPE(Boundary) & ~RT_TYPE(Hair), 2, 3, "Albedo texture",
                        RT_PANEL(Surface))
// Scales roughness by the mean of its channels. A thin sheet has no roughness: there it is its
// thickness, which scales both its absorption and its film point by point
// (roughnessSlotIsThickness; the panel names it so).
RETILE_MATERIAL_TEXTURE(roughnessTexture, "roughness_texture",
                        RT_TYPE(RoughPlastic) | RT_TYPE(RoughConductor) | RT_TYPE(RoughDielectric) | RT_TYPE(OrenNayar) | RT_TYPE(Phong) |
                            RT_TYPE(Hair) | RT_TYPE(ThinSheet),
                        3, 3, "Roughness texture", RT_PANEL(Surface))
// Coverage: its alpha channel, else the mean of its channels.
RETILE_MATERIAL_TEXTURE(alphaTexture, "alpha_texture", RT_ALL_TYPES & ~RT_TYPE(Boundary), 4, 3, "Alpha texture", RT_PANEL(Surface))
// Tilts the shading normal by the slope of this texture's value (the mean of its channels): the
// difference across two texels, scaled by bumpStrength (at 0 it is not packed).
RETILE_MATERIAL_TEXTURE(bumpTexture, "bump_texture", RT_ALL_TYPES & ~RT_TYPE(Boundary), 5, 0, "Bump texture", RT_PANEL(Surface))
// Multiplies emission (glTF's emissiveTexture).
RETILE_MATERIAL_TEXTURE(emissionTexture, "emission_texture", RT_ALL_TYPES & ~RT_TYPE(Boundary), 5, 2, "Emission texture",
                        RT_PANEL(Surface))
// Multiplies blendRatio where the surface is hit by the mean of its channels, read as data. Packed
// only while the material blends.
RETILE_MATERIAL_TEXTURE(blendRatioTexture, "blend_ratio_texture", RT_ALL_TYPES & ~RT_TYPE(Boundary), 7, 0, "Blend ratio texture",
                        RT_PANEL(Custom))

// Rough types: the microfacet distribution. GGX's long tails are the default; Beckmann for files
// that ask for it.
RETILE_MATERIAL_CHOICE(beckmann, "distribution", "ggx", "beckmann", RT_TYPE(RoughPlastic) | RT_TYPE(RoughConductor) | RT_TYPE(RoughDielectric),
                       Beckmann, "Distribution", "GGX", "Beckmann", RT_PANEL(Rough), "")
// Rough types: Smith's masking and shadowing as the product G1(wo) G1(wi) (Tungsten's and Mitsuba
// 0.5's) instead of the height-correlated form (Heitz 2014), which is the more accurate and a
// little brighter at grazing angles.
RETILE_MATERIAL_CHOICE(separableShadowing, "shadowing", "correlated", "separable",
                       RT_TYPE(RoughPlastic) | RT_TYPE(RoughConductor) | RT_TYPE(RoughDielectric), Separable, "Shadowing",
                       "Height-correlated", "Separable (Tungsten)", RT_PANEL(Rough), "")
// Glass: albedo tints the reflection as well as the transmission, and radiance is not scaled by
// (n_t / n_i)^2 where it crosses the surface (Tungsten's dielectrics). The two forms agree on
// light that passes in and out again; they differ where a path ends inside, on an emitter within
// the glass (a lamp's bulb): 1 / ior^2 as bright without this. Otherwise albedo tints the
// transmission alone, the physical form. A thin sheet with a film (filmThickness): its
// reflectances squared once more before they interfere (Tungsten's film), much fainter colours
// than the physical (Airy) form's. The panel names it by the type.
RETILE_MATERIAL_CHOICE(tintsReflection, "glass", "physical", "tinted", RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(ThinSheet),
                       TintsReflection, "Glass", "Physical", "Tinted reflection (Tungsten)", RT_PANEL(Custom), "")
