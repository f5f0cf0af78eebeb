// A material's scalar fields, one row each, and every user of a field reads it from its row:
// retile/scene.h declares the member, the native reader and writer, validation, edits and the
// properties panel iterate materialScalars(), packMaterial writes the value to its slot and the
// kernel reads it there as kMaterialSlot_<member>. A new field is a row here, the GLSL that reads
// it and a test. Included by C++ (retile/scene.h) and GLSL (common/scene.glsl), each defining
// RETILE_MATERIAL_SCALAR first: no include guard.
//
// RETILE_MATERIAL_SCALAR(member, key, default, lo, hi, types, texel, component, label, unit, decimals, place, tip)
//   member            Material's float member
//   key               its key in native files (written when it differs from the default)
//   default, lo, hi   a new material's value, and the range every reader and editor keeps it in
//   types             the types it applies to: RT_TYPE(Hair) | ..., or RT_ALL_TYPES (a boundary has
//                     no surface: nothing of one applies to it)
//   texel, component  where packMaterial writes it, clamped to the range, for those types (other
//                     types may use the slot for another field); -1, -1: packed by code
//                     (render_materials.cpp), where the kernel wants it transformed
//   label, unit, decimals  the properties panel's row ("" no unit)
//   place             where the panel shows it: RT_PANEL(Surface) for its types, Coated while
//                     the material has a coat, Emissive while it emits, Bumped beside a bump
//                     texture; Custom: the panel draws it itself (a slider, a compound widget)
//   tip               the panel row's tooltip ("" none)

// Microfacet alpha for rough types, sigma for Oren-Nayar (which alone goes past 1), Phong's lobe
// width, hair's cones' width (its R lobe's angular deviation is pi / 2 times it, at least 0.04).
RETILE_MATERIAL_SCALAR(roughness, "roughness", 0.1, 0.0, 1.6,
                       RT_TYPE(RoughPlastic) | RT_TYPE(RoughConductor) | RT_TYPE(RoughDielectric) | RT_TYPE(OrenNayar) | RT_TYPE(Phong) |
                           RT_TYPE(Hair),
                       -1, -1, "Roughness", "", 3, RT_PANEL(Custom), "")
// The dielectric's index: a plastic's coating, glass, a thin sheet. Below 1 is an interface seen
// from the denser side (air bubbles in ice).
RETILE_MATERIAL_SCALAR(ior, "ior", 1.5, 0.1, 10.0,
                       RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(ThinSheet),
                       -1, -1, "IOR", "", 3, RT_PANEL(Surface), "")
// A clear coat over an opaque type: a smooth dielectric layer of this index (1 or below: none)
// that reflects by Fresnel and through which the material is seen with both directions
// refracted. No light bounces between the coat and what it covers.
RETILE_MATERIAL_SCALAR(coatIor, "coat_ior", 0.0, 0.0, 10.0,
                       RT_TYPE(Lambert) | RT_TYPE(OrenNayar) | RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Conductor) |
                           RT_TYPE(RoughConductor) | RT_TYPE(Mirror) | RT_TYPE(Null) | RT_TYPE(Phong),
                       -1, -1, "Coat IOR", "", 3, RT_PANEL(Surface), "A clear coat over the material; 0 for none")
// Above 0, the coat is rough: its reflection a GGX lobe of this alpha (Smith's G as the product
// of both G1), and what is below seen as through the smooth coat times cos wo / cos wo' (wo toward
// the viewer, wo' inside), which darkens the base at grazing views and is not reciprocal.
RETILE_MATERIAL_SCALAR(coatRoughness, "coat_roughness", 0.0, 0.0, 1.0,
                       RT_TYPE(Lambert) | RT_TYPE(OrenNayar) | RT_TYPE(Plastic) | RT_TYPE(RoughPlastic) | RT_TYPE(Conductor) |
                           RT_TYPE(RoughConductor) | RT_TYPE(Mirror) | RT_TYPE(Null) | RT_TYPE(Phong),
                       -1, -1, "Coat roughness", "", 3, RT_PANEL(Coated), "")
// Phong: the share of albedo reflected as Lambert, in the slot plastics keep their coating's
// internal reflectance in.
RETILE_MATERIAL_SCALAR(diffuseRatio, "diffuse_ratio", 0.2, 0.0, 1.0, RT_TYPE(Phong), 1, 3, "Diffuse ratio", "", 3, RT_PANEL(Surface), "")
// Diffuse transmission: the share of albedo passed through, in the same slot.
RETILE_MATERIAL_SCALAR(transmittance, "transmittance", 0.5, 0.0, 1.0, RT_TYPE(DiffuseTransmission), 1, 3, "Transmittance", "", 3,
                       RT_PANEL(Surface), "")
// Hair: the angle by which its cuticle's scales tilt the lobes: R by -2 of it, TT by 1 and TRT by
// 4. In the slot conductors keep eta's red.
RETILE_MATERIAL_SCALAR(hairTilt, "hair_tilt", 2.0, -45.0, 45.0, RT_TYPE(Hair), 2, 0, "Scale tilt", "degrees", 1, RT_PANEL(Surface),
                       "How far the cuticle's scales lean the highlights along the fibre: the white one towards the tip, the coloured one back")
// Thin sheets: thin-film interference over a film this thick: the sheet's reflectance then
// varies by channel (red, green and blue taken at 650, 510 and 475 nm) and with the angle. 0:
// none. A sheet has no roughness: the film takes its slot, and a roughness texture scales it.
RETILE_MATERIAL_SCALAR(filmThickness, "film_thickness", 0.0, 0.0, 1e5, RT_TYPE(ThinSheet), 1, 0, "Film thickness", "nm", 1,
                       RT_PANEL(Surface), "Thin-film interference over a film this thick: colours that change with the angle, as on a soap bubble; 0 for none")
// Glass or a boundary filled with a medium: the asymmetry of its Henyey-Greenstein phase
// function (-1 back, 0 even, 1 forward).
RETILE_MATERIAL_SCALAR(interiorAnisotropy, "interior_anisotropy", 0.0, -0.99, 0.99,
                       RT_TYPE(Dielectric) | RT_TYPE(RoughDielectric) | RT_TYPE(Boundary), 9, 3, "Interior anisotropy", "", 2,
                       RT_PANEL(Custom), "")
// Coverage: below 1 (or with an alpha texture) the surface is a cut-out.
RETILE_MATERIAL_SCALAR(alpha, "alpha", 1.0, 0.0, 1.0, RT_ALL_TYPES & ~RT_TYPE(Boundary), 1, 2, "Alpha", "", 3, RT_PANEL(Surface), "")
// Scales the slope of the bump texture's value.
RETILE_MATERIAL_SCALAR(bumpStrength, "bump_strength", 1.0, -1e4, 1e4, RT_ALL_TYPES & ~RT_TYPE(Boundary), 5, 1, "Bump strength", "", 3, RT_PANEL(Bumped), "")
// The front's emitted radiance is emission times this: at 0 the light is off and keeps its colour.
RETILE_MATERIAL_SCALAR(emissionStrength, "emission_strength", 1.0, 0.0, 1e6, RT_ALL_TYPES & ~RT_TYPE(Boundary), -1, -1, "Emission", "", 2, RT_PANEL(Custom),
                       "")
// The half-angle about the front's normal of the cone the front emits into: 90 is the whole
// hemisphere; less, a spot with a hard edge. Seen from outside the cone the emitter is dark, and
// light samples from there find nothing.
RETILE_MATERIAL_SCALAR(emissionCone, "emission_cone", 90.0, 0.0, 90.0, RT_ALL_TYPES & ~RT_TYPE(Boundary), -1, -1, "Emission cone half angle", "degrees", 1,
                       RT_PANEL(Emissive),
                       "The half-angle about the normal within which the front emits: 90 lights the whole hemisphere, less makes a spot with a hard edge")
// A blend's share of this material (Material::blendWith), the partner's the rest.
RETILE_MATERIAL_SCALAR(blendRatio, "blend_ratio", 1.0, 0.0, 1.0, RT_ALL_TYPES & ~RT_TYPE(Boundary), 6, 3, "Blend ratio", "", 3, RT_PANEL(Custom), "")
