//! Tests of the autoencoder: presets, shapes, the offset, and the configuration formats.

use burn::prelude::*;

use super::*;

fn device() -> Device {
    Device::default()
}

/// Table 1's strides, kernels and paddings with one or two channels per layer.
fn narrow(k: usize, channels: usize, blocks: usize, mean_offset: bool) -> AutoencoderConfig {
    AutoencoderConfig::convolutional(
        k,
        ConvolutionalConfig::new()
            .with_projection(Some(channels))
            .with_encoder_channels([channels; 3])
            .with_residual_blocks(blocks)
            .with_decoder_channels([channels; 2])
            .with_mean_offset(mean_offset),
    )
}

#[test]
fn a_standardised_network_divides_its_input_and_multiplies_its_output_by_the_scale() {
    let device = device();
    let config = {
        let mut c = narrow(2, 2, 0, true);
        if let Architecture::Convolutional(layers) = &mut c.architecture {
            layers.standardise = Some(true);
        }
        c
    };
    let offset = vec![0.25; INPUT_VALUES];
    let unit = config.init_seeded(5, &device).unwrap().with_offset(&offset).unwrap();
    let scaled = unit.clone().with_scale(&vec![2.0; INPUT_VALUES]).unwrap();
    let latent = Tensor::<2>::from_data(TensorData::new(vec![0.3f32, -0.7], [1, 2]), &device);
    let a: Vec<f32> =
        unit.decode_deviation(latent.clone()).into_data().try_to_vec::<f32>().unwrap();
    let b: Vec<f32> = scaled.decode_deviation(latent).into_data().try_to_vec::<f32>().unwrap();
    assert!(a.iter().zip(&b).all(|(a, b)| (2.0 * a - b).abs() <= 1e-6 * a.abs().max(1.0)));
    let centred = Tensor::<4>::random(
        [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE],
        burn::tensor::Distribution::Uniform(-1.0, 1.0),
        &device,
    );
    let a: Vec<f32> = unit.encode_centred(centred.clone()).into_data().try_to_vec::<f32>().unwrap();
    let b: Vec<f32> = scaled.encode_centred(centred * 2.0).into_data().try_to_vec::<f32>().unwrap();
    assert!(a.iter().zip(&b).all(|(a, b)| (a - b).abs() <= 1e-5 * a.abs().max(1.0)), "{a:?} {b:?}");
    // A scale needs a standardising configuration, positive values and the layout's length.
    let plain = narrow(2, 2, 0, true).init_seeded(5, &device).unwrap();
    assert!(plain.with_scale(&vec![2.0; INPUT_VALUES]).is_err());
    assert!(unit.clone().with_scale(&vec![0.0; INPUT_VALUES]).is_err());
    assert!(unit.with_scale(&[2.0]).is_err());
    let mut no_offset = config.clone();
    if let Architecture::Convolutional(layers) = &mut no_offset.architecture {
        layers.mean_offset = false;
    }
    assert!(no_offset.validate().is_err());
}

#[test]
fn the_presets_differ_in_architecture_only_and_share_what_the_paper_fixes() {
    let (paper, slice) = (AutoencoderConfig::paper(10), AutoencoderConfig::slice(10));
    // What they share: k and the leaky ReLU slope.
    assert_eq!((paper.latent, paper.negative_slope), (slice.latent, slice.negative_slope));
    assert_eq!(paper.latent, 10);
    // What differs: Table 1's convolutions against the slice network, nothing else.
    let Architecture::Convolutional(table1) = &paper.architecture else {
        panic!("the paper preset is convolutional: {paper}")
    };
    assert_eq!(table1.projection, None);
    assert_eq!(table1.encoder_channels, [256, 128, 64]);
    assert_eq!(table1.residual_blocks, 3);
    assert_eq!(table1.decoder_channels, [128, 256]);
    assert!(!table1.mean_offset && !table1.he_init);
    assert!(!paper.mean_offset() && paper.slice_config().is_none());
    let layers = slice.slice_config().expect("the slice preset is a slice network");
    assert_eq!((layers.directions, layers.components), (SLICE_DIRECTIONS, 40));
    assert!(!slice.mean_offset());
    // The slice preset holds no convolution widths.
    let json = slice.to_string();
    for unused in ["encoder_channels", "projection", "residual_blocks", "convolutional"] {
        assert!(!json.contains(unused), "{json}");
    }
    assert!(matches!(slice.init(&device()).unwrap(), Autoencoder::Slice(_)));
    paper.validate().unwrap();
    AutoencoderConfig::slice(40).validate().unwrap();
    assert!(AutoencoderConfig::paper(0).validate().is_err());
    assert!(narrow(2, 0, 1, true).validate().is_err());
}

#[test]
fn configurations_round_trip_and_retired_formats_are_refused_with_what_to_do() {
    for config in [AutoencoderConfig::paper(5), AutoencoderConfig::slice(20), narrow(3, 2, 1, true)]
    {
        let back: AutoencoderConfig = serde_json::from_str(&config.to_string()).unwrap();
        assert_eq!(back, config);
    }
    // The retired `cpu` preset's network, and the flat format of earlier versions.
    let spectral = r#"{"latent":10,"negative_slope":0.01,
        "architecture":{"spectral":{"directions":96,"hidden":256,"he_init":true}}}"#;
    let flat = r#"{"latent":3,"projection":2,"encoder_channels":[2,2,2],"residual_blocks":1,
        "decoder_channels":[2,2],"mean_offset":true}"#;
    for retired in [spectral, flat] {
        let err = serde_json::from_str::<AutoencoderConfig>(retired).unwrap_err().to_string();
        assert!(err.contains("retired format") && err.contains("--preset slice"), "{err}");
    }
    // A misspelt field; an unknown architecture.
    let typo = AutoencoderConfig::slice(3).to_string().replace("\"hidden\"", "\"hiden\"");
    let err = serde_json::from_str::<AutoencoderConfig>(&typo).unwrap_err().to_string();
    assert!(err.contains("unknown field `architecture.slice.hiden`"), "{err}");
    let unknown = r#"{"latent":3,"architecture":{"recurrent":{}}}"#;
    let err = serde_json::from_str::<AutoencoderConfig>(unknown).unwrap_err().to_string();
    assert!(err.contains("recurrent") && err.contains("convolutional"), "{err}");
}

#[test]
fn shapes_follow_table_1_with_a_narrow_network() {
    let model = narrow(3, 2, 1, true).init_seeded(1, &device()).unwrap();
    assert_eq!(model.latent(), 3);
    let x = Tensor::<4>::ones([1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE], &device());
    let z = model.encode(x.clone(), x.clone());
    assert_eq!(z.dims(), [1, 3]);
    let y = model.decode(z);
    assert_eq!(y.dims(), [1, INPUT_CHANNELS, INPUT_SIDE, INPUT_SIDE]);
}

#[test]
fn offset_is_added_to_the_output_and_rejected_when_absent() {
    let config = narrow(2, 1, 0, true);
    let model = config.init_seeded(2, &device()).unwrap();
    let z = Tensor::<2>::zeros([1, 2], &device());
    let base: Vec<f32> = model.decode(z.clone()).into_data().try_into_vec().unwrap();
    let offset: Vec<f32> = (0..INPUT_VALUES).map(|i| (i % 7) as f32).collect();
    let model = model.with_offset(&offset).unwrap();
    let shifted: Vec<f32> = model.decode(z).into_data().try_into_vec().unwrap();
    for i in [0, 1, 5, 12345, INPUT_VALUES - 1] {
        assert!((shifted[i] - base[i] - offset[i]).abs() < 1e-5, "value {i}");
    }
    assert!(model.with_offset(&[0.0; 3]).is_err());
    let plain = narrow(2, 1, 0, false).init_seeded(2, &device()).unwrap();
    assert!(plain.with_offset(&offset).is_err());
}
