//! Loading Mitsuba scenes: parameters, transforms, materials, errors and 0.x upgrades.

use super::*;
use crate::conductor_ior::named_conductor;
use crate::material::{Scattering, MIN_ALPHA};
use glam::Vec2;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const SCENE: &str = r#"<scene version="3.0.0">
  <default name="spp" value="16"/>
  <default name="r" value="0.25"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective">
<float name="fov" value="45"/>
<transform name="to_world"><lookat origin="0, 1, 5" target="0, 1, 0" up="0, 1, 0"/></transform>
<sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
<film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="twosided" id="grey"><bsdf type="diffuse"><rgb name="reflectance" value="$r, 0.5, 0.5"/></bsdf></bsdf>
  <shape type="rectangle">
<transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/><translate y="0.5"/></transform>
<ref id="grey"/>
  </shape>
  <shape type="cube">
<bsdf type="roughconductor"><float name="alpha" value="0.2"/><string name="distribution" value="ggx"/></bsdf>
  </shape>
  <emitter type="constant"><rgb name="radiance" value="2"/></emitter>
</scene>"#;

#[test]
fn parses_parameters_transforms_and_materials() {
    let dir = std::env::temp_dir().join(format!("nprt-mi-{}", std::process::id()));
    let p = write(&dir, "s.xml", SCENE);
    let opts = SceneOptions {
        set: vec![("r".into(), "0.75".into())],
        ..SceneOptions::default()
    };
    let s = load(&p, &opts).unwrap();
    assert_eq!(s.max_depth, Some(4));
    assert_eq!(s.spp, Some(16));
    let cam = s.camera.as_ref().unwrap();
    assert_eq!((cam.width, cam.height), (64, 32));
    assert!((cam.origin() - Vec3::new(0.0, 1.0, 5.0)).length() < 1e-6);
    // Scale, then rotate -90° about X (z=0 plane → y=0 plane facing +Y), then translate.
    let floor = &s.meshes[0];
    assert!(floor
        .positions
        .iter()
        .all(|p| (p.y - 0.5).abs() < 1e-6 && p.x.abs() <= 2.0 + 1e-6));
    assert!((floor.normals[0] - Vec3::Y).length() < 1e-6);
    let m = s.materials[floor.material].eval(Vec2::ZERO);
    assert_eq!(m.kd, Vec3::new(0.75, 0.5, 0.5));
    assert!(s.materials[floor.material].two_sided);
    let metal = s.materials[s.meshes[1].material].eval(Vec2::ZERO);
    assert_eq!((metal.ks, metal.alpha), (Vec3::ONE, 0.2));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.envmap.as_ref().unwrap().eval(Vec3::X), Vec3::splat(2.0));
}

#[test]
fn errors_name_file_line_and_element() {
    let dir = std::env::temp_dir().join(format!("nprt-mi-err-{}", std::process::id()));
    let bad = SCENE.replace(r#"<bsdf type="roughconductor">"#, r#"<bsdf type="hair">"#);
    let p = write(&dir, "bad.xml", &bad);
    let err = format!("{:#}", load(&p, &SceneOptions::default()).unwrap_err());
    assert!(err.contains("bad.xml:17:") && err.contains("hair"), "{err}");

    let p = write(
        &dir,
        "missing.xml",
        &SCENE.replace(
            r#"<shape type="cube">"#,
            r#"<shape type="ply"><string name="filename" value="nope.ply"/>"#,
        ),
    );
    let err = format!("{:#}", load(&p, &SceneOptions::default()).unwrap_err());
    assert!(
        err.contains("nope.ply") && err.contains("does not exist"),
        "{err}"
    );

    let opts = SceneOptions {
        set: vec![("unknown".into(), "1".into())],
        ..SceneOptions::default()
    };
    let err = format!(
        "{:#}",
        load(&write(&dir, "ok.xml", SCENE), &opts).unwrap_err()
    );
    assert!(err.contains("no parameter 'unknown'"), "{err}");

    let p = write(&dir, "unset.xml", &SCENE.replace("$spp", "$nosuch"));
    let err = format!("{:#}", load(&p, &SceneOptions::default()).unwrap_err());
    assert!(err.contains("$nosuch"), "{err}");
    // Values that are not finite numbers (1e40 overflows f32) stop at the file and line.
    for v in ["nan", "inf", "-inf", "1e40", "1, nan, 1"] {
        let bad = SCENE.replace(
            r#"<rgb name="radiance" value="2"/>"#,
            &format!(r#"<rgb name="radiance" value="{v}"/>"#),
        );
        let err = format!(
            "{:#}",
            load(
                &write(&dir, "nonfinite.xml", &bad),
                &SceneOptions::default()
            )
            .unwrap_err()
        );
        assert!(
            err.contains("nonfinite.xml:19:") && err.contains("not a finite number"),
            "{v}: {err}"
        );
    }
}

#[test]
fn deep_nesting_is_refused_not_a_stack_overflow() {
    let dir = std::env::temp_dir().join(format!("nprt-mi-deep-{}", std::process::id()));
    let n = 3000;
    let deep = format!(
        r#"<scene version="3.0.0"><shape type="cube">{}<bsdf type="diffuse"/>{}</shape></scene>"#,
        r#"<bsdf type="twosided">"#.repeat(n),
        "</bsdf>".repeat(n)
    );
    let err = format!(
        "{:#}",
        load(&write(&dir, "deep.xml", &deep), &SceneOptions::default()).unwrap_err()
    );
    assert!(
        err.contains("deep.xml:1:") && err.contains("more than 100 levels"),
        "{err}"
    );
}

#[test]
fn mitsuba_0x_property_names_upgrade_as_mitsuba_3() {
    for (old, new) in [
        ("toWorld", "to_world"),
        ("maxDepth", "max_depth"),
        ("intIOR", "int_ior"),
        ("specularReflectance", "specular_reflectance"),
        ("fovAxis", "fov_axis"),
        ("uoffset", "uoffset"),
        ("to_world", "to_world"),
    ] {
        assert_eq!(snake_case(old), new);
    }
}

/// A scene in Bitterli's Mitsuba 0.5 style: camelCase names, glass, a mask over a nested
/// BSDF declared with an id, a bump-map wrapper nobody references, complex-index copper and
/// a light portal (a black rectangle carrying an area emitter).
#[test]
fn loads_mitsuba_0_5_scenes_with_glass_masks_and_portals() {
    let text = r#"<scene version="0.5.0">
  <integrator type="path"><integer name="maxDepth" value="7"/></integrator>
  <sensor type="perspective"><float name="fov" value="50"/>
<transform name="toWorld"><lookAt origin="0, 1, 5" target="0, 1, 0" up="0, 1, 0"/></transform>
<sampler type="independent"><integer name="sampleCount" value="8"/></sampler>
<film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="dielectric" id="Glass"><float name="intIOR" value="1.5"/><float name="extIOR" value="1"/>
<rgb name="specularTransmittance" value="0, 0, 0"/></bsdf>
  <bsdf type="thindielectric" id="Pane"><string name="intIOR" value="bk7"/></bsdf>
  <bsdf type="mask" id="Blinds"><spectrum name="opacity" value="0.6"/>
<bsdf type="twosided"><bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.6, 0.5, 0.4"/></bsdf></bsdf></bsdf>
  <bsdf type="bumpmap"><float name="scale" value="1"/>
<bsdf type="twosided" id="Cushion"><bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.1, 0.1"/></bsdf></bsdf></bsdf>
  <bsdf type="twosided" id="Copper"><bsdf type="roughconductor"><float name="alpha" value="0.1"/>
<string name="distribution" value="ggx"/>
<rgb name="eta" value="0.2, 0.92, 1.1"/><rgb name="k" value="3.9, 2.45, 2.14"/></bsdf></bsdf>
  <shape type="rectangle"><ref id="Glass"/></shape>
  <shape type="rectangle"><ref id="Pane"/></shape>
  <shape type="rectangle"><ref id="Blinds"/></shape>
  <shape type="rectangle"><ref id="Cushion"/></shape>
  <shape type="rectangle"><ref id="Copper"/></shape>
  <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
<emitter type="area"><spectrum name="radiance" value="16"/></emitter></shape>
</scene>"#;
    let s = parse(
        text,
        Path::new("kitchen-like.xml"),
        &SceneOptions::default(),
    )
    .unwrap();
    assert_eq!((s.max_depth, s.spp), (Some(7), Some(8)));
    assert!((s.camera.as_ref().unwrap().origin() - Vec3::new(0.0, 1.0, 5.0)).length() < 1e-6);
    assert_eq!(s.meshes.len(), 5, "the portal is removed");
    let at = |i: usize| {
        let m = &s.materials[s.meshes[i].material];
        (m, m.eval(Vec2::ZERO))
    };
    let (glass, g) = at(0);
    assert_eq!(
        g.scattering,
        Scattering::Dielectric {
            eta: 1.5,
            thin: false
        }
    );
    assert!(!glass.two_sided && g.kt == Vec3::ZERO && g.ks == Vec3::ONE);
    let (kd, ks, alpha) = g.gbuffer();
    assert!(kd == Vec3::ZERO && (ks - Vec3::splat(0.04)).abs().max_element() < 1e-6);
    assert_eq!(alpha, MIN_ALPHA);
    let (_, pane) = at(1);
    assert!(
        matches!(pane.scattering, Scattering::Dielectric { eta, thin: true } if (eta - 1.5046 / 1.000277).abs() < 1e-6)
    );
    let (blinds, b) = at(2);
    assert!(blinds.two_sided && (b.opacity - 0.6).abs() < 1e-6);
    assert_eq!(b.kd, Vec3::new(0.6, 0.5, 0.4));
    assert!((b.gbuffer().0 - Vec3::new(0.36, 0.3, 0.24)).length() < 1e-6);
    assert_eq!(at(3).1.kd, Vec3::new(0.5, 0.1, 0.1));
    let (copper, c) = at(4);
    assert!(copper.two_sided && c.alpha == 0.1);
    let f0 = c.gbuffer().1;
    assert!(
        f0.x > f0.y && f0.y > f0.z && f0.x < 1.0,
        "copper's F0 is reddish: {f0}"
    );
    assert!(s.warnings.iter().any(|w| w.contains("area emitter")));
    assert!(s.warnings.iter().any(|w| w.contains("without an id")));

    // Used by a shape, a bump map needs its height texture, and records which wrapper is
    // outside: twosided(bumpmap(…)) mirrors the bumps seen from behind.
    let with = |shape: &str| {
        let t = text.replace(r#"<ref id="Cushion"/>"#, shape);
        parse(&t, Path::new("k.xml"), &SceneOptions::default())
    };
    let err = with(r#"<bsdf type="bumpmap"><bsdf type="diffuse"/></bsdf>"#).unwrap_err();
    assert!(
        format!("{err:#}").contains("k.xml:")
            && format!("{err:#}").contains("needs exactly one nested texture"),
        "{err:#}"
    );
    let checker = r#"<texture type="checkerboard" name="map"/>"#;
    for (shape, two_sided, mirrored) in [
        (
            format!(
                r#"<bsdf type="bumpmap"><float name="scale" value="0.3"/>{checker}<bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>"#
            ),
            true,
            false,
        ),
        (
            format!(
                r#"<bsdf type="twosided"><bsdf type="bumpmap">{checker}<bsdf type="diffuse"/></bsdf></bsdf>"#
            ),
            true,
            true,
        ),
        (
            format!(r#"<bsdf type="bumpmap">{checker}<bsdf type="diffuse"/></bsdf>"#),
            false,
            false,
        ),
    ] {
        let s = with(&shape).unwrap();
        let m = &s.materials[s.meshes[3].material];
        let bump = m.bump.as_ref().expect("bumped");
        assert_eq!(
            (m.two_sided, bump.mirrored_behind),
            (two_sided, mirrored),
            "{shape}"
        );
        assert!(matches!(bump.height, Texture::Checkerboard { .. }));
        assert_eq!(bump.scale, if shape.contains("0.3") { 0.3 } else { 1.0 });
    }
    let err = with(&format!(
        r#"<bsdf type="bumpmap">{checker}<bsdf type="mask"><bsdf type="diffuse"/></bsdf></bsdf>"#
    ))
    .unwrap_err();
    assert!(
        format!("{err:#}").contains("mask inside a bump map"),
        "{err:#}"
    );
    // Conductors named as in Mitsuba 3 take its complex index; unknown names are refused.
    let named = |m: &str| {
        with(&format!(
            r#"<bsdf type="roughconductor"><string name="material" value="{m}"/></bsdf>"#
        ))
    };
    let s = named("Au").unwrap();
    assert_eq!(
        s.materials[s.meshes[3].material].scattering,
        Scattering::Conductor {
            eta: named_conductor("Au").unwrap().0,
            k: named_conductor("Au").unwrap().1
        }
    );
    let err = named("Unobtainium").unwrap_err();
    assert!(
        format!("{err:#}").contains("unknown conductor material 'Unobtainium'")
            && format!("{err:#}").contains("Cu_palik"),
        "{err:#}"
    );
    // Mitsuba 3 names are not renamed in a 0.x file's camelCase world, nor the reverse.
    let v3 = text.replace("0.5.0", "3.0.0");
    let s3 = parse(&v3, Path::new("k.xml"), &SceneOptions::default()).unwrap();
    assert_eq!(
        s3.max_depth, None,
        "maxDepth means nothing to a version-3 file"
    );
}
