//! A minimal ash program (no dermis code) that shows lavapipe's shader leak, and
//! the workaround dermis uses. See docs/reliability.md ("Resident memory").
//!
//! lavapipe in Mesa 22.3.6 (Debian 12's) compiles a fresh copy of a fragment
//! shader (LLVM code and data, about 430 KB here) every time a command buffer
//! that binds a descriptor set of it executes, and never frees it, when the
//! shader is large enough and branches on a uniform-buffer value alone: its
//! "inline uniforms" optimisation bakes the values in, once per bind. A frame
//! that binds such a set N times leaks N shaders.
//!
//! ```sh
//! cargo run --features tools --example lavapipe_inline_leak -- uniform 1000   # ~860 KB per frame
//! cargo run --features tools --example lavapipe_inline_leak -- opaque 1000    # flat
//! ```
//!
//! The shader is cut down from dermis' geometry pass: a shadow lookup, and a
//! per-object `skin` flag in the material's uniform buffer selecting the output
//! alpha (glslang compiles `skin ? a : b` with loads into a branch). Each frame
//! binds the frame's set, then draws two objects, binding each one's material set.
//! `uniform`: `skin` is the buffer's value, and the shader leaks twice a frame.
//! `opaque`: `min(gl_FragCoord.x, 0.0)`, which is 0 in every fragment, is added to
//! the value first, so the branch no longer depends on uniforms alone (dermis'
//! workaround, shaders/driver_workarounds.glsl). Prints the resident set size
//! every 200 frames and the growth per frame since frame 10.

use std::ffi::CStr;
use std::io::Write;

use ash::vk;

const SHADER: &str = r#"#version 450
// Cut down from dermis' geometry pass (shaders/geometry_body.glsl, lighting.glsl).
layout(set = 0, binding = 0) uniform Frame {
    mat4 lightViewProj;
    vec4 lightDir;
    vec4 cameraPos;
    vec4 lightColor;
    vec4 ambient;
    vec4 shadowParams;  // x: texel, y: bias
} frame;
layout(set = 0, binding = 1) uniform texture2D shadowMap;
layout(set = 0, binding = 2) uniform sampler nearestClamp;
layout(set = 1, binding = 0) uniform texture2D albedoTex;
layout(set = 1, binding = 1) uniform sampler materialSampler;
layout(set = 1, binding = 2) uniform Material {
    vec4 baseColor;
    vec4 params;  // z: SSS strength, w: 1 for skin
} material;
layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec2 vUv;
layout(location = 0) out vec4 outDiffuse;
layout(location = 1) out vec4 outSpecular;
layout(location = 2) out float outDepth;

float shadowPcf(vec3 worldPos) {
    vec4 p = frame.lightViewProj * vec4(worldPos, 1.0);
    vec3 c = vec3(p.xy * 0.5 + 0.5, p.z);
    float texel = frame.shadowParams.x;
    float ref = min(c.z - frame.shadowParams.y, 1.0);
    float sum = 0.0;
    for (int y = -1; y <= 1; y++)
        for (int x = -1; x <= 1; x++)
            sum += textureLod(sampler2D(shadowMap, nearestClamp), c.xy + vec2(x, y) * texel, 0.0).r * ref;
    return sum / 9.0;
}

void main() {
    vec3 N = normalize(vNormal);
    vec3 albedo = textureLod(sampler2D(albedoTex, materialSampler), vUv, 0.0).rgb * material.baseColor.rgb;
    vec3 L = normalize(frame.lightDir.xyz);
    vec3 V = normalize(frame.cameraPos.xyz - vWorldPos);
    float shadow = shadowPcf(vWorldPos);
#if defined(OPAQUE)
    bool skin = material.params.w + min(gl_FragCoord.x, 0.0) > 0.5;  // min(...) is 0
#else
    bool skin = material.params.w > 0.5;
#endif
    vec3 diffuse = albedo * (frame.lightColor.rgb * max(dot(N, L), 0.0) * shadow + frame.ambient.rgb);
    float specMask = textureLod(sampler2D(albedoTex, materialSampler), vUv, 0.0).g;
    outDiffuse = vec4(diffuse, skin ? material.params.z : 0.0);
    outSpecular = vec4(frame.lightColor.rgb * specMask * dot(N, V) * shadow, 1.0);
    outDepth = vWorldPos.z;
}
"#;

const VERTEX: &str = r#"#version 450
layout(location = 0) out vec3 vWorldPos;
layout(location = 1) out vec3 vNormal;
layout(location = 2) out vec2 vUv;
void main() {
    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    vWorldPos = vec3(p, 1.0);
    vNormal = vec3(p - 0.5, 1.0);
    vUv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"#;

fn compile(source: &str, stage: &str, define: Option<&str>) -> Vec<u32> {
    let dir = std::env::temp_dir().join(format!("lvp-inline-leak-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let src = dir.join(format!("s.{stage}"));
    let out = dir.join(format!("s.{stage}.spv"));
    std::fs::write(&src, source).expect("write shader");
    let mut cmd = std::process::Command::new("glslangValidator");
    cmd.arg("-V").arg("-o").arg(&out).arg(&src);
    if let Some(d) = define {
        cmd.arg(format!("-D{d}"));
    }
    let result = cmd
        .output()
        .expect("glslangValidator (Debian: glslang-tools)");
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stdout)
    );
    let bytes = std::fs::read(&out).expect("read spv");
    let _ = std::fs::remove_dir_all(&dir);
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

fn rss_kib() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: u64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    pages * 4
}

struct Gpu {
    instance: ash::Instance,
    device: ash::Device,
    memory: vk::PhysicalDeviceMemoryProperties,
}

impl Gpu {
    unsafe fn alloc(
        &self,
        req: vk::MemoryRequirements,
        flags: vk::MemoryPropertyFlags,
    ) -> vk::DeviceMemory {
        let index = (0..self.memory.memory_type_count)
            .find(|&i| {
                req.memory_type_bits & (1 << i) != 0
                    && self.memory.memory_types[i as usize]
                        .property_flags
                        .contains(flags)
            })
            .expect("memory type");
        self.device
            .allocate_memory(
                &vk::MemoryAllocateInfo::default()
                    .allocation_size(req.size)
                    .memory_type_index(index),
                None,
            )
            .expect("memory")
    }

    unsafe fn image(
        &self,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> (vk::Image, vk::DeviceMemory, vk::ImageView) {
        let format = vk::Format::R8G8B8A8_UNORM;
        let image = self
            .device
            .create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(extent.into())
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .usage(usage),
                None,
            )
            .expect("image");
        let memory = self.alloc(
            self.device.get_image_memory_requirements(image),
            vk::MemoryPropertyFlags::empty(),
        );
        self.device
            .bind_image_memory(image, memory, 0)
            .expect("bind image");
        let view = self
            .device
            .create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format)
                    .subresource_range(color_range()),
                None,
            )
            .expect("view");
        (image, memory, view)
    }
}

fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(vk::ImageAspectFlags::COLOR)
        .level_count(1)
        .layer_count(1)
}

fn barrier(image: vk::Image, layout: vk::ImageLayout) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
        .old_layout(vk::ImageLayout::UNDEFINED)
        .new_layout(layout)
        .image(image)
        .subresource_range(color_range())
}

// Long because it is the whole program, in the order Vulkan needs it (device,
// images, sets, pipeline, frame loop, teardown), read top to bottom.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let variant = args.get(1).map(String::as_str).unwrap_or("uniform");
    let frames: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let define = match variant {
        "uniform" => None,
        "opaque" => Some("OPAQUE"),
        other => panic!("variant must be uniform or opaque, got {other}"),
    };
    unsafe {
        let entry = ash::Entry::load().expect("Vulkan loader");
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
        let instance = entry
            .create_instance(
                &vk::InstanceCreateInfo::default().application_info(&app),
                None,
            )
            .expect("instance");
        let physical = instance
            .enumerate_physical_devices()
            .expect("devices")
            .into_iter()
            .find(|&p| {
                let props = instance.get_physical_device_properties(p);
                CStr::from_ptr(props.device_name.as_ptr())
                    .to_string_lossy()
                    .contains("llvmpipe")
            })
            .expect("lavapipe (Debian: mesa-vulkan-drivers)");
        let props = instance.get_physical_device_properties(physical);
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        instance.get_physical_device_properties2(physical, &mut props2);
        println!(
            "{} | {} | variant {variant}",
            CStr::from_ptr(props.device_name.as_ptr()).to_string_lossy(),
            CStr::from_ptr(driver.driver_info.as_ptr()).to_string_lossy()
        );
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(0)
            .queue_priorities(&priorities)];
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true);
        let device = instance
            .create_device(
                physical,
                &vk::DeviceCreateInfo::default()
                    .queue_create_infos(&queues)
                    .push_next(&mut f13),
                None,
            )
            .expect("device");
        let queue = device.get_device_queue(0, 0);
        let gpu = Gpu {
            memory: instance.get_physical_device_memory_properties(physical),
            instance,
            device,
        };
        let device = &gpu.device;

        // Three 64x36 targets (the geometry pass's diffuse, specular and depth)
        // and a 4x4 texture read as the shadow map and the material maps.
        let extent = vk::Extent2D {
            width: 64,
            height: 36,
        };
        let targets: Vec<_> = (0..3)
            .map(|_| gpu.image(extent, vk::ImageUsageFlags::COLOR_ATTACHMENT))
            .collect();
        let (texture, texture_memory, texture_view) = gpu.image(
            vk::Extent2D {
                width: 4,
                height: 4,
            },
            vk::ImageUsageFlags::SAMPLED,
        );
        let sampler = device
            .create_sampler(
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::LINEAR)
                    .min_filter(vk::Filter::LINEAR),
                None,
            )
            .expect("sampler");

        // Set 0: the frame's uniforms, shadow map and sampler. Set 1: a material
        // (map, sampler, uniforms); two of them, skin and backdrop.
        let layout_of = |kinds: [vk::DescriptorType; 3]| {
            let bindings: Vec<_> = kinds
                .iter()
                .enumerate()
                .map(|(b, &t)| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b as u32)
                        .descriptor_type(t)
                        .descriptor_count(1)
                        .stage_flags(vk::ShaderStageFlags::FRAGMENT)
                })
                .collect();
            device
                .create_descriptor_set_layout(
                    &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                    None,
                )
                .expect("set layout")
        };
        use vk::DescriptorType as D;
        let frame_kinds = [D::UNIFORM_BUFFER, D::SAMPLED_IMAGE, D::SAMPLER];
        let material_kinds = [D::SAMPLED_IMAGE, D::SAMPLER, D::UNIFORM_BUFFER];
        let set_layouts = [layout_of(frame_kinds), layout_of(material_kinds)];
        let sizes =
            [D::UNIFORM_BUFFER, D::SAMPLED_IMAGE, D::SAMPLER].map(|ty| vk::DescriptorPoolSize {
                ty,
                descriptor_count: 3,
            });
        let descriptor_pool = device
            .create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(3)
                    .pool_sizes(&sizes),
                None,
            )
            .expect("descriptor pool");
        let sets = device
            .allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(descriptor_pool)
                    .set_layouts(&[set_layouts[0], set_layouts[1], set_layouts[1]]),
            )
            .expect("sets");
        let mut frame_data = [0.0f32; 36];
        for i in 0..4 {
            frame_data[i * 5] = 1.0; // lightViewProj = identity
        }
        frame_data[16..20].copy_from_slice(&[0.5, 0.5, 0.7, 0.0]); // lightDir
        frame_data[20..24].copy_from_slice(&[0.0, 0.0, 5.0, 1.0]); // cameraPos
        frame_data[24..28].copy_from_slice(&[2.5, 2.4, 2.3, 0.0]); // lightColor
        frame_data[28..32].copy_from_slice(&[0.08; 4]); // ambient
        frame_data[32..36].copy_from_slice(&[1.0 / 2048.0, 0.001, 1.0, 0.0]); // shadowParams
        let skin = [0.62, 0.4, 0.32, 1.0, 0.3, 0.18, 0.8, 1.0];
        let backdrop = [0.35, 0.35, 0.35, 1.0, 0.6, 0.02, 0.0, 0.0];
        let uniforms: [&[f32]; 3] = [&frame_data, &skin, &backdrop];
        let mut buffers = Vec::new();
        for (i, (data, &set)) in uniforms.iter().zip(&sets).enumerate() {
            let size = (data.len() * 4) as u64;
            let buffer = device
                .create_buffer(
                    &vk::BufferCreateInfo::default()
                        .size(size)
                        .usage(vk::BufferUsageFlags::UNIFORM_BUFFER),
                    None,
                )
                .expect("buffer");
            let memory = gpu.alloc(
                device.get_buffer_memory_requirements(buffer),
                vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT,
            );
            device.bind_buffer_memory(buffer, memory, 0).expect("bind");
            let ptr = device
                .map_memory(memory, 0, size, vk::MemoryMapFlags::empty())
                .expect("map") as *mut f32;
            std::ptr::copy_nonoverlapping(data.as_ptr(), ptr, data.len());
            device.unmap_memory(memory);
            buffers.push((buffer, memory));
            let buffer_info = [vk::DescriptorBufferInfo {
                buffer,
                offset: 0,
                range: size,
            }];
            let image_info = [vk::DescriptorImageInfo {
                sampler,
                image_view: texture_view,
                image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            }];
            let kinds = if i == 0 { frame_kinds } else { material_kinds };
            let writes: Vec<_> = kinds
                .iter()
                .enumerate()
                .map(|(b, &t)| {
                    let w = vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(b as u32)
                        .descriptor_type(t);
                    if t == D::UNIFORM_BUFFER {
                        w.buffer_info(&buffer_info)
                    } else {
                        w.image_info(&image_info)
                    }
                })
                .collect();
            device.update_descriptor_sets(&writes, &[]);
        }

        // The pipeline: a full-screen triangle and the fragment shader above.
        let vs_code = compile(VERTEX, "vert", None);
        let fs_code = compile(SHADER, "frag", define);
        let vs = device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&vs_code), None)
            .expect("vs");
        let fs = device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&fs_code), None)
            .expect("fs");
        let layout = device
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts),
                None,
            )
            .expect("layout");
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vs)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs)
                .name(c"main"),
        ];
        let vi = vk::PipelineVertexInputStateCreateInfo::default();
        let ia = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let vp = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let rs = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .line_width(1.0);
        let ms = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let blend = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA); 3];
        let cb = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
        let dynamic = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let ds = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
        let formats = [vk::Format::R8G8B8A8_UNORM; 3];
        let mut rendering =
            vk::PipelineRenderingCreateInfo::default().color_attachment_formats(&formats);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vi)
            .input_assembly_state(&ia)
            .viewport_state(&vp)
            .rasterization_state(&rs)
            .multisample_state(&ms)
            .color_blend_state(&cb)
            .dynamic_state(&ds)
            .layout(layout)
            .push_next(&mut rendering);
        let pipeline = device
            .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
            .expect("pipeline")[0];

        let pool = device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
            .expect("pool");
        let cmd = device
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .command_buffer_count(1),
            )
            .expect("cmd")[0];
        let fence = device
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .expect("fence");

        // The frame loop: record, submit, wait. Nothing is allocated per frame.
        let mut first = 0;
        for frame in 0..=frames {
            device
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .expect("reset");
            device
                .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .expect("begin");
            let barriers = [
                barrier(targets[0].0, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                barrier(targets[1].0, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                barrier(targets[2].0, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                barrier(texture, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
            ];
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&barriers),
            );
            let attachments = targets.iter().map(|t| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(t.2)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
            });
            let attachments: Vec<_> = attachments.collect();
            device.cmd_begin_rendering(
                cmd,
                &vk::RenderingInfo::default()
                    .render_area(extent.into())
                    .layer_count(1)
                    .color_attachments(&attachments),
            );
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
            device.cmd_set_viewport(
                cmd,
                0,
                &[vk::Viewport {
                    x: 0.0,
                    y: 0.0,
                    width: extent.width as f32,
                    height: extent.height as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                }],
            );
            device.cmd_set_scissor(cmd, 0, &[extent.into()]);
            // The frame's set once, then two objects, each with its material's
            // set (as dermis' geometry pass).
            device.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                layout,
                0,
                &sets[..1],
                &[],
            );
            for &set in &sets[1..] {
                device.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    layout,
                    1,
                    &[set],
                    &[],
                );
                device.cmd_draw(cmd, 3, 1, 0, 0);
            }
            device.cmd_end_rendering(cmd);
            device.end_command_buffer(cmd).expect("end");
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
            device.queue_submit2(queue, &submit, fence).expect("submit");
            device
                .wait_for_fences(&[fence], true, u64::MAX)
                .expect("wait");
            device.reset_fences(&[fence]).expect("reset fence");
            if frame == 10 {
                first = rss_kib();
            }
            if frame % 200 == 0 {
                let now = rss_kib();
                let per = if frame > 10 {
                    (now as f64 - first as f64) / (frame - 10) as f64
                } else {
                    0.0
                };
                println!(
                    "frame {frame:6}: RSS {:8.1} MiB ({per:.1} KiB/frame since frame 10)",
                    now as f64 / 1024.0
                );
                let _ = std::io::stdout().flush();
            }
        }
        device.destroy_fence(fence, None);
        device.destroy_command_pool(pool, None);
        device.destroy_pipeline(pipeline, None);
        device.destroy_pipeline_layout(layout, None);
        device.destroy_shader_module(vs, None);
        device.destroy_shader_module(fs, None);
        device.destroy_descriptor_pool(descriptor_pool, None);
        for l in set_layouts {
            device.destroy_descriptor_set_layout(l, None);
        }
        for (buffer, memory) in buffers {
            device.destroy_buffer(buffer, None);
            device.free_memory(memory, None);
        }
        device.destroy_sampler(sampler, None);
        for (image, memory, view) in
            targets
                .into_iter()
                .chain([(texture, texture_memory, texture_view)])
        {
            device.destroy_image_view(view, None);
            device.destroy_image(image, None);
            device.free_memory(memory, None);
        }
        device.destroy_device(None);
        gpu.instance.destroy_instance(None);
    }
}
